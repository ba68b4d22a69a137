"""A renderer keeps what it derives per object (key, program, packed uniforms) across frames
(`glphong.gpu.drawing.draw_list`); these tests change everything that may change between frames and compare with a
fresh renderer, image for image (bit-identical), on both backends.

- the camera (reassigned or replaced), lights added, the ambient light replaced, objects added: the same
  image as a renderer that never saw the earlier frames;
- a pose cannot be changed in place (it is read-only: move an object by adding it again);
- a program's uniforms that did not change are not written again (GL keeps them), and a uniform
  written by another path (`Program.bind`) is not mistaken for unchanged.
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.shaders.binding import binding


def _scene():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.5, 4.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 2.0), 80.0)])
    for x, material in ((-1.0, glphong.Phong(0.2, 0.5, 40.0)), (1.0, glphong.Lambert((0.1, 0.2, 0.3)))):
        pose = np.eye(4)
        pose[0, 3] = x
        scene.add(primitives.sphere(3, 0.6), material, pose=pose)
    return scene


def _fresh(scene, backend, make_renderer):
    return make_renderer(64, 48, backend).render(scene).radiance


def test_frames_follow_every_change(glphong_backend, glphong_make_renderer):
    scene = _scene()
    renderer = glphong_make_renderer(64, 48, glphong_backend)
    first = renderer.render(scene).radiance
    assert np.array_equal(renderer.render(scene).radiance, first)
    scene.camera = glphong.PerspectiveCamera.look_at((0.5, 1.0, 3.5), (0.0, 0.0, 0.0))
    moved = renderer.render(scene).radiance
    assert not np.array_equal(moved, first) and np.array_equal(moved, _fresh(scene, glphong_backend, glphong_make_renderer))
    scene.add_light(glphong.DirectionalLight((0.0, -1.0, -1.0), 0.5))
    lit = renderer.render(scene).radiance
    assert not np.array_equal(lit, moved) and np.array_equal(lit, _fresh(scene, glphong_backend, glphong_make_renderer))
    scene.ambient = glphong.AmbientLight(0.2)
    ambient = renderer.render(scene).radiance
    assert np.array_equal(ambient, _fresh(scene, glphong_backend, glphong_make_renderer))
    scene.add(primitives.sphere(2, 0.3), glphong.BlinnPhong(0.1, 0.4, 100.0))
    more = renderer.render(scene).radiance
    assert np.array_equal(more, _fresh(scene, glphong_backend, glphong_make_renderer))
    gbuffer = renderer.gbuffer(scene)  # the G-buffer's entries are kept apart from the radiance's
    assert np.array_equal(renderer.render(scene).radiance, more) and gbuffer.mask.any()


def test_pose_is_read_only():
    obj = _scene().objects[0]
    with pytest.raises(ValueError, match="read-only"):
        obj.pose[0, 3] = 5.0


def test_unchanged_uniforms_are_not_written_again(glphong_backend, glphong_make_renderer):
    scene = _scene()
    renderer = glphong_make_renderer(32, 32, glphong_backend)
    renderer.render(scene)
    program = renderer.programs.get(renderer.program_key(scene, scene.objects[0]))
    calls = []
    for name, uniform in program.active.items():
        original = uniform.write
        uniform.write = lambda data, name=name, original=original: (calls.append(name), original(data))
    renderer.render(scene)
    assert calls == []  # one object per program here: nothing changed since the last frame
    with renderer.context:
        values = binding(scene).uniform_values(0, program.key, 1.0)
        values["u_eye"] = np.zeros(4, np.float32)
        program.bind(values)  # another path writes a uniform: the next frame must restore it
    assert "u_eye" in calls
    calls.clear()
    image = renderer.render(scene).radiance
    assert calls == ["u_eye"] and np.array_equal(image, glphong_make_renderer(32, 32, glphong_backend).render(scene).radiance)


def test_readback_is_one_writable_array(glphong_backend, glphong_make_renderer):
    """radiance and coverage are views of the one readback (no copy after the driver's), writable, row 0 at
    the top: the sphere's lit top half is brighter than its bottom half."""
    frame = glphong_make_renderer(64, 48, glphong_backend).render(_scene())
    assert frame.radiance.base is frame.coverage.base and np.may_share_memory(frame.radiance, frame.coverage)
    frame.radiance[0, 0] = 1.0  # writable
    light_side = frame.radiance[:24].sum()
    assert light_side > frame.radiance[24:].sum() > 0
