"""The documentation site builds with warnings as errors, and every ``python`` block of its pages runs.

The build is the one ``docs/conf.py`` documents (``sphinx-build -W --keep-going -b html docs OUT``), run in a
subprocess into a temporary folder: the API reference from the numpydoc docstrings, the Markdown pages and
sphinx-gallery over ``examples/`` (every example executed, every time, each showing its picture).  The python
blocks of ``docs/*.md`` run as the README's do (``tests/test_readme.py``): each in a fresh interpreter in an
empty temporary folder.
"""
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
OPENING = re.compile(r"^```(\S*)")
BUILD_PACKAGES = ("sphinx", "numpydoc", "sphinx_gallery", "myst_parser", "matplotlib")


def code_blocks(path, language):
    """The fenced blocks of ``language`` in a Markdown file, as (first line number, source) pairs.

    Fences are paired line by line, so MyST directives (```{toctree}) pair like any other block."""
    blocks, current, start, fence = [], None, 0, None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if current is None:
            match = OPENING.match(line)
            if match:
                current, start, fence = [], number + 1, match.group(1)
        elif line.rstrip() == "```":
            if fence == language:
                blocks.append((start, "\n".join(current) + "\n"))
            current = None
        else:
            current.append(line)
    return blocks


PAGES = sorted(DOCS.glob("*.md"))
PYTHON_BLOCKS = [(page.name, line, source) for page in PAGES for line, source in code_blocks(page, "python")]


def test_the_pages_have_their_python_blocks():
    pages = {page for page, _, _ in PYTHON_BLOCKS}
    assert {"textures.md", "batches.md", "reflectance_models.md", "measured_brdfs.md", "custom_material.md",
            "pyrender.md"} <= pages
    assert len(PYTHON_BLOCKS) >= 7


@pytest.mark.parametrize("page, line, source", PYTHON_BLOCKS,
                         ids=[f"{page}:{line}" for page, line, _ in PYTHON_BLOCKS])
def test_docs_python_block_runs(page, line, source, tmp_path):
    if "import pyrender" in source and importlib.util.find_spec("pyrender") is None:
        pytest.skip("pyrender is not installed (pip install 'glphong[pyrender]')")
    out = subprocess.run([sys.executable, "-c", source], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, f"docs/{page}:{line} failed:\n{out.stderr[-3000:]}"


def test_the_site_builds(tmp_path):
    missing = [name for name in BUILD_PACKAGES if importlib.util.find_spec(name) is None]
    assert not missing, f"the docs build needs {missing}: pip install '.[docs]' (also in '.[test]')"
    html = tmp_path / "html"
    # run_stale_examples: the gallery's examples run in every build, not only when their source changed
    out = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html",
                          "-D", "sphinx_gallery_conf.run_stale_examples=1", str(DOCS), str(html)],
                         cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert out.returncode == 0, f"sphinx-build failed:\n{out.stdout[-2000:]}\n{out.stderr[-4000:]}"

    pages = ["index", "install", "changelog", "command_line", "design", "files", "how_it_is_tested", "speed",
             "brdf", "api/index", "api/glphong", "api/materials", "api/testing", "api/batch", "api/filesafety",
             "api/imaging", "api/radiometry", "api/pyrender", "auto_examples/index", "auto_examples/tutorial",
             "definitions/index", "definitions/materials/phong_lobe", "definitions/lights/spot"]
    pages += [f"auto_examples/{p.stem}" for p in (ROOT / "examples").glob("*.py")]
    pages += [f"api/generated/glphong.{name}" for name in ("Scene", "Renderer", "Frame", "PerspectiveCamera",
                                                           "PointLight", "Phong", "verify", "load_scene",
                                                           "save_gltf", "describe", "MaterialModel", "Param",
                                                           "Texture", "testing.assert_twin_matches",
                                                           "batch.render_many", "filesafety.SceneFileError",
                                                           "imaging.encode_srgb8", "radiometry.point_irradiance",
                                                           "integrations.pyrender.GlphongMaterial",
                                                           "materials.PhongLobe")]
    absent = [page for page in pages if not (html / f"{page}.html").is_file()]
    assert absent == [], f"pages the site lacks: {absent}"

    # the tutorial's renders, shown through matplotlib, and the examples' own PNG files are embedded
    tutorial = (html / "auto_examples" / "tutorial.html").read_text(encoding="utf-8")
    assert tutorial.count("sphx_glr_tutorial_00") >= 5
    # every example shows what it makes (one whose optional dependency is missing is shown un-run: docs/conf.py)
    optional = {"pyrender_scene": "pyrender", "custom_material": "pyrender", "test_my_shader": "hypothesis"}
    shown = [p.stem for p in sorted((ROOT / "examples").glob("*.py"))
             if importlib.util.find_spec(optional.get(p.stem, "glphong")) is not None]
    assert len(shown) >= 8
    blank = [example for example in shown if not (html / "_images" / f"sphx_glr_{example}_001.png").is_file()]
    assert blank == [], f"gallery examples that show no picture: {blank}"
    # the definition contract in MaterialModel's docstring is on its page (numpydoc drops sections it does not
    # know; docs/conf.py keeps them)
    material_model = (html / "api" / "generated" / "glphong.MaterialModel.html").read_text(encoding="utf-8")
    assert "Lowercase GLSL prefix" in material_model and "The numpy twin" in material_model
