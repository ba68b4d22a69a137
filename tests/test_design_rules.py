"""The rules of docs/design.md sections 6 (architecture) and 7 (tests) that a file's text can show, read from
the design document where it states them.

- No module of ``glphong/`` is longer than the limit section 6 states ("No module is above about 600 lines"),
  the limit read from that sentence;
- every GLSL file under ``glsl/`` opens with a header comment that names the file and says what it computes, and
  names every define its preprocessor conditionals read (section 6: "Every file opens with its formula, units and
  the defines it reads");
- every library chunk and stage file section 6 lists is a file of ``glsl/``;
- every test module, benchmark and file that sections 6 and 7 name exists (``tests/materials/test_<model>.py``
  standing for the folder's modules).

The rest of section 6 is held elsewhere: the layers, the import cycles and the imports at the top of modules by
``tests/test_layers.py``, the moved public paths by ``tests/test_moved_paths.py``.
"""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "glphong"
GLSL = ROOT / "glsl"
DESIGN = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")


def _section(number):
    """The text of section ``number`` of docs/design.md, from its ``## N.`` heading to the next ``## ``."""
    match = re.search(rf"^## {number}\. .*?(?=^## )", DESIGN, re.M | re.S)
    assert match, f"docs/design.md has no section {number}"
    return match.group(0)


ARCHITECTURE, TESTS = _section(6), _section(7)


def _module_line_limit():
    """The limit section 6 states: "No module is above about 600 lines ..."."""
    match = re.search(r"No module is (?:above|longer than) (?:about )?(\d+) lines", ARCHITECTURE)
    assert match, "docs/design.md section 6 no longer states a module's line limit as 'No module is above N lines'"
    return int(match.group(1))


def test_no_module_is_longer_than_the_design_allows():
    limit = _module_line_limit()
    lengths = {path.relative_to(ROOT).as_posix(): len(path.read_text(encoding="utf-8").splitlines())
               for path in sorted(PACKAGE.rglob("*.py"))}
    assert len(lengths) > 60
    offenders = {path: n for path, n in lengths.items() if n > limit}
    assert offenders == {}, f"modules longer than {limit} lines (docs/design.md section 6): split them: {offenders}"


def test_the_module_limit_is_read_from_the_design_document():
    assert _module_line_limit() == 600


# --- the shaders ------------------------------------------------------------------------------------------------
SHADERS = sorted(GLSL.rglob("*.glsl"))
#: a preprocessor conditional and the defines it reads (macro names are upper case; GL_ES is GLSL's own)
CONDITIONAL = re.compile(r"^\s*#\s*(?:if|ifdef|ifndef|elif)\b(.*)$", re.M)
DEFINE_NAME = re.compile(r"\b[A-Z][A-Z0-9]*_[A-Z0-9_]*\b|\b[A-Z]{3,}[0-9]*\b")
BUILT_IN = {"GL_ES"}


def _header(text):
    """The comment a GLSL file opens with: its leading ``//`` lines."""
    lines = []
    for line in text.splitlines():
        if not line.startswith("//"):
            break
        lines.append(line)
    return lines


def _defines_read(text):
    names = set()
    for expression in CONDITIONAL.findall(text):
        names |= set(DEFINE_NAME.findall(expression.split("//")[0]))
    return names - BUILT_IN


def test_the_shaders_are_found():
    assert len(SHADERS) > 30
    assert _defines_read("#if NAIVE_LIGHT\n#elif defined(POINT_RANGE) && N > 0 // TWO_SIDED\n#endif\n") == {
        "NAIVE_LIGHT", "POINT_RANGE"}


@pytest.mark.parametrize("path", SHADERS, ids=lambda p: p.relative_to(GLSL).as_posix())
def test_every_shader_opens_with_its_header(path):
    """``// <path under glsl/> -- <what it computes>`` and more lines: the formula, the units, the defines."""
    header = _header(path.read_text(encoding="utf-8"))
    name = path.relative_to(GLSL).as_posix()
    assert header and re.match(rf"// {re.escape(name)} -- \S", header[0]), (
        f"glsl/{name} must open with '// {name} -- <what it computes>' (docs/design.md section 6)")
    assert len(header) >= 3, f"glsl/{name}: its header comment gives no formula"


@pytest.mark.parametrize("path", SHADERS, ids=lambda p: p.relative_to(GLSL).as_posix())
def test_every_shader_header_names_the_defines_it_reads(path):
    text = path.read_text(encoding="utf-8")
    header = "\n".join(_header(text))
    unnamed = sorted(name for name in _defines_read(text) if not re.search(rf"\b{name}\b", header))
    assert unnamed == [], (f"glsl/{path.relative_to(GLSL).as_posix()} reads {unnamed} in #if lines, which its "
                           "header comment does not name (docs/design.md section 6: 'Key defines read here: ...')")


def test_the_chunks_the_design_lists_are_shipped():
    """Section 6: "the library chunks are `common`, ... and `shade`; the stage files `mesh_vertex`, ..."."""
    listed = re.search(r"the library chunks are (.*?); the stage files (.*?); each model", ARCHITECTURE, re.S)
    assert listed, "docs/design.md section 6 no longer lists the library chunks and the stage files"
    names = re.findall(r"`(\w+)`", listed.group(1) + listed.group(2))
    assert len(names) >= 15
    missing = [name for name in names if not (GLSL / f"{name}.glsl").is_file()]
    assert missing == []
    assert sorted(GLSL.glob("materials/*.glsl")), "each model has one file under glsl/materials/"


# --- the files sections 6 and 7 name ----------------------------------------------------------------------------
NAMED = sorted({path or config for path, config in re.findall(
    r"`((?:tests|benchmarks|docs)/[\w/<>.-]+\.(?:py|md))`|`(\.importlinter)`", ARCHITECTURE + TESTS)})


def test_the_sections_name_files():
    assert "tests/test_layers.py" in NAMED and "benchmarks/mutation.py" in NAMED and len(NAMED) > 15


@pytest.mark.parametrize("name", NAMED)
def test_every_file_the_sections_name_exists(name):
    pattern = re.sub(r"<\w+>", "*", name)
    assert sorted(ROOT.glob(pattern)), f"docs/design.md sections 6-7 name {name}, which the project lacks"
