"""The speed family's peers (glphong.bench.peers): PyVista (in the test extra) and Open3D (the bench extra only;
skipped with the reason where it is not installed).  Each draws the family's scenes with the settings matched to
glphong's, reads back an 8-bit image of the right size with the object where glphong shows it, and coexists with
glphong's renderers made after it.  Each runs in a process of its own: a VTK plotter made on EGL terminates the
display every context of the process shares (this worker's pooled contexts too), and Open3D keeps its renderer for
the process."""
import importlib.util
import subprocess
import sys

import numpy as np
import pytest

import glphong
from glphong.bench.peers import Open3DRenderer, PyVistaRenderer, diffuse_colour, posed_triangles
from glphong.bench.speed import speed_scenes

SIZE = 48
PEERS = (PyVistaRenderer, Open3DRenderer)  # what the subprocesses take from this module (`_in_a_process`)


def _check_against_glphong(peer_class, **options):
    scene = speed_scenes(quick=True)["sphere"]
    peers = [peer_class(SIZE, SIZE, **options).prepare(scene), peer_class(SIZE, SIZE).prepare(scene)]
    renderer = glphong.Renderer(SIZE, SIZE, backend="egl")  # made after the peers (module docstring)
    try:
        mask = renderer.render(scene).mask
        for peer in peers:
            image = peer.render()
            assert image.shape == (SIZE, SIZE, 3) and image.dtype == np.uint8
            lit = image.max(axis=-1) > 12  # Open3D dithers its background by a few codes
            assert (lit & mask).sum() > 0.8 * mask.sum() and (lit & ~mask).sum() < 0.2 * mask.sum()
            again = peer.render().astype(np.int64)  # a frame again: the same pixels, up to Open3D's dithering
            assert np.abs(again - image).max() <= 2
    finally:
        renderer.release()
        for peer in peers:
            peer.release()


def _in_a_process(call):
    out = subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {str(__file__.rsplit('/', 1)[0])!r}); "
                          f"import test_peers as t; {call}; print('checked')"], capture_output=True, text=True,
                         timeout=300, env={**__import__("os").environ, "EGL_PLATFORM": "surfaceless"})
    assert out.returncode == 0 and "checked" in out.stdout, out.stderr[-3000:]


def test_pyvista_draws_the_scene_where_glphong_does():
    pytest.importorskip("pyvista", reason="PyVista is not installed (the extra 'bench' or 'test')")
    _in_a_process("t._check_against_glphong(t.PyVistaRenderer, anti_aliasing=False)")


@pytest.mark.skipif(importlib.util.find_spec("open3d") is None,
                    reason="Open3D is not installed (the extra 'bench'; 0.19 on llvmpipe: 0.20 needs Vulkan)")
def test_open3d_draws_the_scene_where_glphong_does():
    _in_a_process("t._check_against_glphong(t.Open3DRenderer, post_processing=False)")


def test_the_matched_settings():
    scene = speed_scenes(quick=True)["100 spheres"]
    obj = scene.objects[3]
    positions, normals, faces = posed_triangles(obj)
    assert np.allclose(positions, obj.mesh.positions @ obj.pose[:3, :3].T + obj.pose[:3, 3], atol=1e-6)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0) and faces.shape == (obj.mesh.triangle_count, 3)
    assert diffuse_colour(glphong.Lambert(0.1)) == pytest.approx((np.pi * 0.1,) * 3)
    assert diffuse_colour(glphong.Lambert(0.5)) == (1.0, 1.0, 1.0)
    with pytest.raises(ImportError, match="pip install 'glphong\\[bench\\]'") if importlib.util.find_spec(
            "open3d") is None else pytest.raises(ValueError, match="point lights only"):
        Open3DRenderer(8, 8).prepare(glphong.Scene(scene.camera, [glphong.DirectionalLight((0, 0, -1), 1.0)]))
