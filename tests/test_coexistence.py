"""glphong beside other OpenGL users in one process: PyVista (VTK's EGL render window) and pyrender's
OffscreenRenderer, made and deleted before or after a glphong Renderer, leave glphong's EGL context working.

Each case runs in a subprocess: pyrender pins PyOpenGL's platform, and VTK's EGL state is process-wide.
"""
import importlib.util
import os
import subprocess
import sys

import pytest

_SCRIPT = r"""
import gc, os, sys
library, order = sys.argv[1], sys.argv[2]
if library == "pyrender":
    os.environ["PYOPENGL_PLATFORM"] = "egl"
import numpy as np, glphong
from glphong import primitives
scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [glphong.PointLight((2, 2, 2), 100.0)])
scene.add(primitives.sphere(2), glphong.Lambert(0.3))


def use_other():
    '''Make, render with, and delete the other library's offscreen renderer; return its image's mean.'''
    if library == "pyvista":
        import pyvista
        plotter = pyvista.Plotter(off_screen=True, window_size=(32, 32))
        plotter.add_mesh(pyvista.Sphere())
        image = plotter.screenshot(return_img=True)
        plotter.close()
    else:
        import pyrender, trimesh
        other = pyrender.Scene()
        other.add(pyrender.Mesh.from_trimesh(trimesh.creation.icosphere()))
        other.add(pyrender.PerspectiveCamera(yfov=1.0), pose=np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 3], [0, 0, 0, 1.0]]))
        offscreen = pyrender.OffscreenRenderer(32, 32)
        image, _ = offscreen.render(other)
        offscreen.delete()               # eglTerminate on the device's display
    gc.collect()
    return float(np.asarray(image, dtype=float).mean())


if order == "other_first":
    print("OTHER", use_other() > 0)
renderer = glphong.Renderer(32, 32, backend="egl")
before = renderer.render(scene).radiance.copy()
print("OTHER", use_other() > 0)          # after glphong's context exists (and again in the other order)
try:
    print("SAME", np.array_equal(renderer.render(scene).radiance, before) and before.max() > 0)
except Exception as exc:
    print("REFUSED", type(exc).__name__, " ".join(str(exc).split()))
renderer.release()
"""


def _case(library, order, **env):
    out = subprocess.run([sys.executable, "-c", _SCRIPT, library, order], capture_output=True, text=True,
                         timeout=180, env={**os.environ, **env})
    assert out.returncode == 0, out.stderr[-3000:]
    return [line for line in out.stdout.splitlines() if line.split()[0] in ("OTHER", "SAME", "REFUSED")]


def _need(module, make_context):
    if importlib.util.find_spec(module) is None:
        pytest.skip(f"{module} is not installed (pip install 'glphong[{'pyrender' if module == 'pyrender' else 'bench'}]')")
    make_context("egl")  # skips (or fails where required) without EGL


@pytest.mark.parametrize("order", ["other_first", "glphong_first"])
@pytest.mark.parametrize("library", ["pyvista", "pyrender"])
def test_other_library_does_not_end_glphong(make_context, library, order):
    """Both orders: the other library renders (its image is not black) and glphong's renderer, made before the
    other library deleted its renderer, draws the same image as before (it raised EGLDisplayTerminatedError when
    glphong shared the display)."""
    _need(library, make_context)
    lines = _case(library, order)
    expected = ["OTHER True"] * (2 if order == "other_first" else 1) + ["SAME True"]
    assert lines == expected


def test_shared_display_names_the_library(make_context):
    """Where glphong must share the display (GLPHONG_EGL_DISPLAY=shared stands in for a driver that offers no
    display of its own), VTK's close() ends glphong's context and the error names VTK / PyVista."""
    _need("pyvista", make_context)
    lines = _case("pyvista", "glphong_first", GLPHONG_EGL_DISPLAY="shared")
    assert lines[0] == "OTHER True"
    assert lines[1].startswith("REFUSED EGLDisplayTerminatedError"), lines
    assert "VTK / PyVista" in lines[1] and "pyrender (" not in lines[1]
