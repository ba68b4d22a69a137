"""Every citation of the design document, and every ``docs/`` path the project names, resolves inside the project.

The code, shaders, tests and README cite ``docs/design.md section N`` (or ``sections N and M``) and the
labelled equations ``docs/design.md E1`` to ``E6``; each must name a heading ``## N.`` or a bold label
``**E1**`` of ``docs/design.md``, and nothing may cite a design document the project does not hold.  Any
other page or file they name (``docs/scenes_from_files.md``, ``docs/phong_examples.png``) must exist.
"""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DESIGN = ROOT / "docs" / "design.md"
SOURCES = [p for folder in ("glphong", "glsl", "tests", "examples", "benchmarks") for p in (ROOT / folder).rglob("*")
           if p.suffix in (".py", ".glsl", ".rst", ".md", ".txt")] + [ROOT / "README.md"]
SECTIONS = re.compile(r"design\.md\)? sections? (\d+)((?:(?:, | and )\d+)*)")
EQUATIONS = re.compile(r"design\.md\)? (E\d+)")
#: a path under docs/ written out in full (``docs/files.md``, ``docs/bench/brdf_answers.json``): one built at run
#: time (``f"docs/{page}.md"``, ``DOCS / name``) has no literal file name after ``docs/`` and is not matched
DOC_PATH = re.compile(r"(?<![\w/.{-])docs/((?:[\w.-]+/)*[\w-]+(?:\.[\w-]+)*\.[A-Za-z0-9]+)")
#: what sphinx-build writes (docs/_build/html/index.html in a comment on how to look at the site)
BUILT = ("_build/",)


def _citations():
    for path in SOURCES:
        text = path.read_text(encoding="utf-8")
        for match in SECTIONS.finditer(text):
            for number in [match.group(1)] + re.findall(r"\d+", match.group(2)):
                yield path, ("section", int(number))
        for match in EQUATIONS.finditer(text):
            yield path, ("equation", match.group(1))


CITATIONS = list(_citations())


def test_the_project_cites_its_own_design_document():
    assert len(CITATIONS) > 80
    stale = [str(p.relative_to(ROOT)) for p in SOURCES if re.search(r"DESIGN (sections? \d|E\d)", p.read_text("utf-8"))]
    assert stale == [], f"citations of a design document outside the project: {stale}"


def test_every_citation_resolves():
    text = DESIGN.read_text(encoding="utf-8")
    headings = {int(n) for n in re.findall(r"^## (\d+)\. ", text, re.M)}
    labels = set(re.findall(r"\*\*(E\d+)\*\*", text))
    missing = sorted({(str(p.relative_to(ROOT)), kind, what) for p, (kind, what) in CITATIONS
                      if (kind == "section" and what not in headings) or (kind == "equation" and what not in labels)})
    assert missing == [], f"citations that docs/design.md cannot resolve: {missing}"


@pytest.mark.parametrize("number", range(1, 13))
def test_design_document_has_its_sections(number):
    assert re.search(rf"^## {number}\. \S", DESIGN.read_text(encoding="utf-8"), re.M)


def doc_paths(text):
    """The ``docs/`` paths written out in ``text``, relative to ``docs/``, but those of the built site."""
    return [path for path in DOC_PATH.findall(text) if not path.startswith(BUILT)]


def test_doc_paths_are_found():
    text = ("see docs/design.md section 3, docs/bench/brdf_answers.json and (docs/phong_examples.png). "
            "Built into docs/_build/html/index.html; f'docs/{page}.md', DOCS / 'api', mydocs/x.md")
    assert doc_paths(text) == ["design.md", "bench/brdf_answers.json", "phong_examples.png"]


def test_every_cited_docs_path_exists():
    cited = sorted({(str(p.relative_to(ROOT)), path) for p in SOURCES for path in doc_paths(p.read_text("utf-8"))})
    assert len(cited) > 30
    missing = [(source, f"docs/{path}") for source, path in cited if not (ROOT / "docs" / path).exists()]
    assert missing == [], f"docs/ paths cited that the project does not hold (file, path): {missing}"
