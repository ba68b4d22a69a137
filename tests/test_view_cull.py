"""Triangles out of the view left out of the draw (`glphong.gpu.view_cull`): the test against a float64 clipper, and
the frames unchanged bit for bit."""
import math

import numpy as np
import pytest

import glphong
import glphong.gpu.drawing as drawing
from glphong.gpu.view_cull import box_inside, visible_triangles
from glphong.scene.camera import PerspectiveCamera


def _meets_volume(triangle):
    """Whether a clip-space triangle (3, 4) meets the clip volume: Sutherland-Hodgman against its six planes in
    float64 (an independent check: the polygon left after every plane is empty or not)."""
    polygon = [np.asarray(v, np.float64) for v in triangle]
    for axis in range(3):
        for sign in (1.0, -1.0):
            distance = lambda v: v[3] - sign * v[axis]  # noqa: E731 - >= 0 inside the plane
            out = []
            for a, b in zip(polygon, polygon[1:] + polygon[:1]):
                da, db = distance(a), distance(b)
                if da >= 0:
                    out.append(a)
                if (da >= 0) != (db >= 0):
                    out.append(a + (b - a) * (da / (da - db)))
            polygon = out
            if not polygon:
                return False
    return True


def test_kept_triangles_are_those_that_may_meet_the_view():
    rng = np.random.default_rng(3)
    positions = rng.uniform(-3.0, 3.0, (600, 3))
    indices = rng.integers(0, len(positions), (2000, 3)).astype(np.uint32)
    camera = PerspectiveCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), yfov=math.radians(30.0), znear=2.0, zfar=7.0)
    matrix = camera.projection_matrix(1.5) @ camera.view_matrix()
    kept = visible_triangles(positions, indices.reshape(-1), matrix).reshape(-1, 3)
    clip = np.c_[positions, np.ones(len(positions))] @ matrix.T
    meets = np.array([_meets_volume(clip[t]) for t in indices])
    kept_rows = {tuple(t) for t in kept}
    assert all(tuple(t) in kept_rows for t in indices[meets])  # nothing that may be drawn is left out
    assert 0 < meets.sum() < len(kept) < len(indices)  # some are left out, conservatively (a corner may miss)
    assert np.array_equal(kept, indices[np.isin(np.arange(len(indices)), [i for i, t in enumerate(indices)
                                                                          if tuple(t) in kept_rows])])  # in order


def test_box_inside():
    camera = PerspectiveCamera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), yfov=math.radians(40.0))
    matrix = camera.projection_matrix(1.0) @ camera.view_matrix()
    assert box_inside((0.0, 0.0, 0.0), 0.5, matrix)
    assert not box_inside((0.0, 0.0, 0.0), 2.0, matrix)  # 1.46 m of half-height at 4 m: the box reaches out
    assert not box_inside((0.0, 0.0, 5.0), 0.1, matrix)  # behind the camera


def _fine_plane(camera):
    scene = glphong.Scene(camera, [glphong.PointLight((0.8, 0.6, 1.5), 60.0)], glphong.AmbientLight(0.03))
    scene.add(glphong.primitives.plane(4.0, 128), glphong.Phong((0.18, 0.12, 0.08), 0.5, 50.0))
    return scene


@pytest.mark.parametrize("camera, drawn", [
    (PerspectiveCamera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), yfov=math.radians(60.0)), True),
    (PerspectiveCamera.look_at((0.3, -1.2, 0.4), (0.0, 0.5, 0.0), yfov=math.radians(50.0), znear=0.05), True),
    (PerspectiveCamera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 2.0), yfov=math.radians(60.0)), False),  # nothing in view
], ids=["facing", "grazing", "away"])
def test_frames_unchanged(glphong_backend, glphong_make_renderer, camera, drawn, monkeypatch):
    scene = _fine_plane(camera)
    plain = glphong_make_renderer(96, 64, glphong_backend)
    msaa = glphong_make_renderer(96, 64, glphong_backend, samples=4)
    culled = [plain.render(scene).radiance, plain.render_srgb8(scene), msaa.render_srgb8(scene)]
    monkeypatch.setattr(drawing, "MIN_TRIANGLES", 10 ** 9)  # every mesh drawn whole
    whole = [plain.render(scene).radiance, plain.render_srgb8(scene), msaa.render_srgb8(scene)]
    assert culled[1].any() == drawn
    for a, b in zip(culled, whole):
        assert np.array_equal(a, b)


def test_the_test_runs_and_its_buffers_are_replaced(glphong_backend, glphong_make_renderer, monkeypatch):
    monkeypatch.setattr(drawing, "MIN_TRIANGLES", 1000)
    scene = _fine_plane(PerspectiveCamera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), yfov=math.radians(60.0)))
    calls = []
    real = drawing.visible_triangles
    monkeypatch.setattr(drawing, "visible_triangles", lambda *a: calls.append(1) or real(*a))
    renderer = glphong_make_renderer(64, 64, glphong_backend)
    whole = renderer.gl_object_count()
    renderer.render(scene)
    before = renderer.gl_object_count()
    renderer.render(scene)  # the same camera: the kept triangles are reused
    assert len(calls) == 1 and renderer.gl_object_count() == before
    scene.camera = PerspectiveCamera.look_at((0.2, 0.0, 1.0), (0.2, 0.0, 0.0), yfov=math.radians(60.0))
    renderer.render(scene)  # another camera: tested again, the old buffers replaced
    assert len(calls) == 2 and renderer.gl_object_count() == before > whole
    renderer.render_srgb8(scene)  # another program (the display's), the same view: the kept triangles are shared
    renderer.render(scene, passes=("depth", "instance", "object_coordinates"))
    assert len(calls) == 2
