"""The shipped GLSL chunk files: where they are and their text.

The chunks live in ``glsl/`` (installed as the package ``glphong.glsl``); `glsl_root` finds them and
`chunk_source` reads one.  Every program starts with `GLSL_VERSION`.
"""
import functools
import importlib.resources
import os
from pathlib import Path

__all__ = ["GLSL_VERSION", "glsl_root", "chunk_source"]

GLSL_VERSION = "#version 330 core"


def glsl_root():
    """Folder of the chunk files: ``GLPHONG_GLSL_DIR`` when set (a developer's working copy of the
    shaders, used by ``benchmarks/mutation.py``), else the installed ``glphong.glsl`` package, else
    ``glsl/`` beside the package in a source checkout."""
    override = os.environ.get("GLPHONG_GLSL_DIR")
    if override:
        return Path(override)
    try:
        return importlib.resources.files("glphong.glsl")
    except ModuleNotFoundError:  # running from a source checkout: glsl/ beside the package
        return Path(__file__).resolve().parents[2] / "glsl"


@functools.lru_cache(maxsize=None)
def chunk_source(name):
    """Text of the library chunk file ``glsl/<name>.glsl``."""
    return (glsl_root() / f"{name}.glsl").read_text(encoding="utf-8")
