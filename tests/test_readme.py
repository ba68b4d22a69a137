"""The README's front door cannot rot: every ``python`` code block in it runs, extracted from the file.

Each block runs in a fresh interpreter in an empty temporary folder (pyrender fixes its OpenGL platform
once per process, and the blocks write files), so a block that raises, or that refers to a name it does
not define, fails here.  The shell blocks are the install and test commands that ``.ci/run`` runs.
"""
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"
FENCE = re.compile(r"^```(\w*)\n(.*?)^```$", re.S | re.M)


def code_blocks(language):
    """The README's fenced blocks of ``language``, as (first line number, source) pairs."""
    text = README.read_text(encoding="utf-8")
    return [(text[:m.start()].count("\n") + 1, m.group(2)) for m in FENCE.finditer(text) if m.group(1) == language]


PYTHON_BLOCKS = code_blocks("python")


def test_readme_has_its_python_blocks():
    # the 'Use' example; the longer examples moved to the docs pages, whose blocks tests/test_docs.py runs
    assert len(PYTHON_BLOCKS) >= 1
    assert any("glphong.verify(scene" in source for _, source in PYTHON_BLOCKS)


@pytest.mark.parametrize("line, source", PYTHON_BLOCKS, ids=[f"README.md:{line}" for line, _ in PYTHON_BLOCKS])
def test_readme_python_block_runs(line, source, tmp_path):
    if "import pyrender" in source and importlib.util.find_spec("pyrender") is None:
        pytest.skip("pyrender is not installed (pip install 'glphong[pyrender]')")
    out = subprocess.run([sys.executable, "-c", source], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, f"README.md:{line} failed:\n{out.stderr[-3000:]}"


def test_readme_test_command_is_the_one_ci_runs():
    ci = (README.parent / ".ci" / "run").read_text(encoding="utf-8")
    commands = [source.strip() for _, source in code_blocks("sh")]
    test_command = next(c for c in commands if "pytest" in c)
    assert test_command in ci
