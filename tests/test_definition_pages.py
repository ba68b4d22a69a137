"""The pages written from the definitions (``docs/_definitions.py``): one per registered reflectance model and per
light kind, each with its parameter table, written into a temporary folder without Sphinx."""
import importlib.util
import re
from pathlib import Path

import pytest

from glphong.lights import registered_lights
from glphong.materials import registered_models

ROOT = Path(__file__).resolve().parent.parent
_SPEC = importlib.util.spec_from_file_location("_definitions", ROOT / "docs" / "_definitions.py")
definitions = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(definitions)

#: the header row of a parameter table, as the generator writes it (a reST list-table)
HEADER = "   * - name\n     - kind\n     - default\n     - range\n     - unit\n     - meaning\n"


def _builtin(classes):
    return {cls.name: cls for cls in classes if cls.__module__.startswith("glphong.")}


MODELS = _builtin(registered_models())
LIGHTS = _builtin(registered_lights())


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    out = tmp_path_factory.mktemp("definitions")
    return out, definitions.write_pages(out)


def test_one_page_per_model_and_light_kind(pages):
    out, written = pages
    assert len(MODELS) >= 14 and len(LIGHTS) >= 9
    assert set(written["materials"]) == set(MODELS)
    assert set(written["lights"]) == set(LIGHTS)
    files = {p.relative_to(out).as_posix() for p in out.rglob("*.rst")}
    assert files == {f"materials/{n}.rst" for n in MODELS} | {f"lights/{n}.rst" for n in LIGHTS} | {"index.rst"}


def _rows(text, title):
    """The names in the first column of the table under the section ``title``."""
    match = re.search(rf"^{title}\n-+\n\n(\.\. list-table::\n(?:(?:   .*)?\n)+)", text, re.M)
    assert match and HEADER in match.group(1), f"no parameter table under {title!r}"
    section = match.group(1)
    return re.findall(r"^   \* - ``(\w+)``$", section, re.M)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_a_model_page_has_its_docstring_parameter_table_and_uniforms(pages, name):
    cls = MODELS[name]
    text = pages[1]["materials"][name].read_text(encoding="utf-8")
    assert f".. autoclass:: {definitions._public(cls)}" in text
    assert _rows(text, "Parameters") == [a.name for a in cls.arguments()]
    assert f"u_{name}_" in text.split(".. code-block:: glsl", 1)[1] or not cls.uniform_params()
    for p in cls.params:  # each Param's line of documentation and its unit, as the definition states them
        assert p.doc in text.replace("\\", "") and f"     - {p.unit or '1'}\n" in text.replace("\\", "")
    assert "Gallery and the four answers" in text


@pytest.mark.parametrize("name", sorted(LIGHTS))
def test_a_light_page_has_its_docstring_parameter_table_and_uniforms(pages, name):
    cls = LIGHTS[name]
    text = pages[1]["lights"][name].read_text(encoding="utf-8")
    assert f".. autoclass:: {definitions._public(cls)}" in text
    assert _rows(text, "Parameters") == [p.name for p in cls.params]
    if cls.uniforms is not None:
        assert _rows(text, "Uniforms its GLSL reads") == [p.name for p in cls.uniforms]
    assert cls.uniform_declarations().splitlines()[0] in text


def test_the_model_pages_carry_the_recorded_answers(pages):
    text = pages[1]["materials"]["phong_lobe"].read_text(encoding="utf-8")
    assert "*Phong q=60*" in text and "   * - Phong q=60\n     - yes: min 0.0509\n     - **no**: max 1.912" in text
    lambert = pages[1]["materials"]["lambert"].read_text(encoding="utf-8")
    assert "   * - Lambert\n" in lambert and "   * - Phong q=60\n" in lambert  # Phong = Lambert + PhongLobe
    assert "   * - Ward bounded\n" not in lambert


def test_the_index_lists_and_links_every_page(pages):
    text = pages[1]["index"].read_text(encoding="utf-8")
    toctree = text.split(".. toctree::", 1)[1]
    for name in MODELS:
        assert f":doc:`{name} <materials/{name}>`" in text and f"   materials/{name}\n" in toctree
    for name in LIGHTS:
        assert f":doc:`{name} <lights/{name}>`" in text and f"   lights/{name}\n" in toctree
    assert ":class:`~glphong.Phong` = ``Lambert + PhongLobe``" in text


def test_pages_are_rewritten_only_when_changed_and_stale_ones_removed(tmp_path):
    written = definitions.write_pages(tmp_path)
    page = written["lights"]["spot"]
    stale = tmp_path / "materials" / "no_such_model.rst"
    stale.write_text("gone\n")
    before = page.stat().st_mtime_ns
    definitions.write_pages(tmp_path)
    assert page.stat().st_mtime_ns == before and not stale.exists()


def test_user_definitions_get_no_page():
    class Custom:
        __module__ = "my_package.models"

    assert definitions.builtin([Custom, MODELS["lambert"]]) == [MODELS["lambert"]]
