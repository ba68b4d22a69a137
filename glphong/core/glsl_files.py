"""The shipped GLSL chunk files: where they are and their text.

The chunks live in ``glsl/`` (installed as the package ``glphong.glsl``); `glsl_root` finds them and
`chunk_source` reads one.  Every program starts with `GLSL_VERSION`.  `LIBRARY` is the one place that orders
the library chunks and says who may call each.
"""
import functools
import importlib.resources
import os
from pathlib import Path

__all__ = ["GLSL_VERSION", "LIBRARY", "glsl_root", "chunk_source", "library_chunks"]

GLSL_VERSION = "#version 330 core"
#: glphong's library chunks (glsl/<name>.glsl) in include order, a chunk calling only those before it, each with who
#: may name it in its ``uses``: 'model' (a material model, and a light kind), 'light' (a light kind) or None (a
#: program includes it where its key needs it: common.glsl always, normal_map.glsl with a normal map)
LIBRARY = (("common", None), ("lights", "light"), ("lobe", "model"), ("fresnel", "model"), ("angle", "model"),
           ("microfacet", "model"), ("area", "light"), ("normal_map", None))


def library_chunks(user=None):
    """The library chunks in include order: all of them (``user=None``), those a material model may use ('model'),
    or those a light kind may use ('light': its own and the models'), tuple of str."""
    allowed = {None: None, "model": {"model"}, "light": {"model", "light"}}[user]
    return tuple(name for name, who in LIBRARY if allowed is None or who in allowed)


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
