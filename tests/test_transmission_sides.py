"""A one-sided transmissive surface (glTF's ``doubleSided: false``) seen from behind is culled, as a blended one is and
as glTF says ("back-face culling is enabled"): the radiance shows what lies behind it, and so do the G-buffer, the
geometry passes and their twins (`glphong.gpu.transmission.one_sided_transmissive`,
`glphong.checks.frame_twin.culled_back_faces`); a two-sided one is drawn from both sides."""
import numpy as np

import glphong
from glphong import primitives

WIDTH, HEIGHT = 48, 40


def _scene(two_sided, glass=True):
    """A Lambert floor above a glass quad, both facing down (-z) toward a camera below: the camera sees the quad's
    back (its normal is +z)."""
    camera = glphong.PerspectiveCamera.look_at((0.3, -0.4, -2.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((0.5, 0.2, -1.5), 20.0)])
    floor = np.diag([1.0, -1.0, -1.0, 1.0])  # turned over: faces -z
    floor[2, 3] = 1.0
    scene.add(primitives.plane(4.0), glphong.Lambert(0.5), pose=floor, name="floor")
    if glass:
        scene.add(primitives.plane(1.0), glphong.GltfPBR((0.9, 0.9, 1.0), 0.0, 0.0, transmission=1.0,
                                                         two_sided=two_sided), name="glass")
    return scene


def test_a_one_sided_glass_seen_from_behind_is_culled(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _scene(two_sided=False)
    frame = renderer.render(scene, passes=("radiance", "instance"))
    alone = renderer.render(_scene(two_sided=False, glass=False)).radiance
    np.testing.assert_array_equal(frame.radiance, alone)  # the floor alone, bit for bit
    assert not (renderer.gbuffer(scene).object_index == 1).any()
    report = glphong.verify(scene, renderer, passes=("depth", "instance", "normal"))
    assert report.passed, report.summary()


def test_a_two_sided_glass_is_drawn_from_behind(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(WIDTH, HEIGHT, glphong_backend)
    scene = _scene(two_sided=True)
    report = glphong.verify(scene, renderer, passes=("depth", "instance", "normal"))
    assert report.passed, report.summary()
    assert report.transmission.pixels.sum() > 300  # the quad covers about 530 pixels here
    assert (renderer.gbuffer(scene).object_index == 1).sum() > 300
