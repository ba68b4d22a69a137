"""`glphong.verify(scene, renderer, passes=...)`: every geometry pass of a render against its float64 twin
(`glphong.checks.frame_twin`), on both backends; and planted errors in a pass fail it.

The scene moves between three frames (a sphere that rotates and translates, a box beside it, an off-centre OpenCV
camera, a textured quad for 'uv'), so that flow, backward flow, ids, categories and the object's own coordinates are
all non-trivial.
"""
from dataclasses import replace

import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.checks.verify_passes import verify_passes
from glphong.gpu.passes import GEOMETRY_PASSES
from glphong.scene.geometry import MeshData

W, H = 72, 56


def _turn(angle, shift):  # a turn of ``angle`` [rad] about +y, then ``shift`` [m]
    pose = trimesh.transformations.rotation_matrix(angle, (0.0, 1.0, 0.0))
    pose[:3, 3] = shift
    return pose


SPHERE = primitives.sphere(3, 0.5)
BOX = MeshData.from_trimesh(trimesh.creation.box((0.5, 0.4, 0.6)), smooth=False)


def _scene(angle):
    pose = glphong.PerspectiveCamera.look_at((0.3, 0.25, 3.0), (0.0, 0.0, 0.0)).pose
    camera = glphong.IntrinsicsCamera(60.0, 58.0, 33.2, 30.1, W, H, pose=pose)
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(SPHERE, glphong.Phong(0.2, 0.4, 20.0), pose=_turn(angle, (0.3 * angle, 0.0, 0.0)),
              instance_id=7, category=3)
    scene.add(BOX, glphong.Lambert(0.5), pose=_turn(-angle, (-0.6, 0.2, 0.3)), category=5)
    return scene


@pytest.fixture(scope="module")
def frames():
    return _scene(-0.1), _scene(0.0), _scene(0.1)


NAMES = tuple(n for n in GEOMETRY_PASSES if n != "uv")


def test_every_pass_is_within_its_band(glphong_backend, glphong_make_renderer, frames):
    previous, scene, following = frames
    renderer = glphong_make_renderer(W, H, glphong_backend)
    report = glphong.verify(scene, renderer, passes=NAMES, next_scene=following, previous_scene=previous)
    assert report.passed, str(report)
    assert set(report.passes) == set(NAMES)
    for name, check in report.passes.items():
        assert check.passed and check.unchecked.sum() == 0, (name, check.summary())
    assert report.passes["instance"].gpu[report.mask].min() >= 1  # the objects cover pixels
    assert np.abs(report.passes["flow"].reference[report.mask]).max() > 1.0  # they move by more than a pixel
    assert "flow pass" in str(report) and report.summary()["passes"]["depth"]["outside"] == 0


def test_uv_is_within_its_band(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.2, -0.3, 2.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 2.0), 10.0)])
    scene.add(primitives.plane(1.2), glphong.Lambert(0.5))
    report = glphong.verify(scene, glphong_make_renderer(W, H, glphong_backend), passes=["uv", "depth"])
    assert report.passed, str(report)
    uv = report.passes["uv"].gpu[report.mask]
    assert uv.min() < 0.2 and uv.max() > 0.8



@pytest.mark.parametrize("plant", ["depth + 1e-3 m on one pixel", "normal turned 0.01 rad", "instance swapped",
                                   "category of the background", "flow off by 0.01 px", "object point moved 1e-3 m",
                                   "flow NaN in front of the camera"])
def test_planted_errors_fail(glphong_make_renderer, frames, plant):
    previous, scene, following = frames
    renderer = glphong_make_renderer(W, H, "egl")
    frame = renderer.render(scene, passes=NAMES, next_scene=following, previous_scene=previous)
    covered = np.argwhere(frame.mask & (frame.instance == 7))
    y, x = covered[len(covered) // 2]
    if plant.startswith("depth"):
        name, value = "depth", frame.depth.copy()
        value[y, x] += 1e-3
    elif plant.startswith("normal"):
        name, value = "normal", frame.normal.copy()
        n = value[y, x].astype(np.float64)
        side = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
        value[y, x] = np.cos(0.01) * n + np.sin(0.01) * side / np.linalg.norm(side)
    elif plant == "instance swapped":
        name, value = "instance", frame.instance.copy()
        value[y, x] = 1  # the box's id, where only the sphere is seen
    elif plant.startswith("category"):
        name, value = "category", frame.category.copy()
        value[0, 0] = 3  # a background pixel
    elif plant == "flow off by 0.01 px":
        name, value = "flow", frame.flow.copy()
        value[y, x, 0] += 0.01
    elif plant.startswith("object"):
        name, value = "object_coordinates", frame.object_coordinates.copy()
        value[y, x, 2] += 1e-3
    else:
        name, value = "flow", frame.flow.copy()
        value[y, x] = np.nan
    assert not frame.mask[0, 0]
    good = verify_passes(scene, frame, (name,), following, previous)[name]
    assert good.passed, good.summary()
    report = verify_passes(scene, replace(frame, **{name: value}), (name,), following, previous)[name]
    assert not report.passed and report.outside_count == 1 and report.outside[y if name != "category" else 0,
                                                                               x if name != "category" else 0]


def test_flow_against_the_wrong_next_scene_fails(glphong_make_renderer, frames):
    previous, scene, following = frames
    renderer = glphong_make_renderer(W, H, "egl")
    frame = renderer.render(scene, passes=("flow",), next_scene=following)
    report = verify_passes(scene, frame, ("flow",), next_scene=previous)["flow"]
    assert not report.passed and report.outside_count > 100
