"""The orthographic camera (`glphong.OrthographicCamera`): parallel rays and one view direction.

Against the closed forms written here and the exact ray cast:

- a Phong plane under a directional light, seen straight down: every covered pixel is
  ``kd (n.l) E + ks (v.r)^q E`` with the one view direction ``v = +z`` (to 2e-6 relative; a perspective
  camera's highlight varies across the same plane), the plane covers exactly ``2 ymag`` by
  ``2 ymag aspect`` metres, and depth is the distance along the axis;
- a Blinn-Phong sphere: the GPU against the float64 twin on its G-buffer (`glphong.verify`) and against the
  ray cast of the exact sphere with parallel rays (relative RMS 5e-3 at icosphere level 5);
- pyrender's OrthographicCamera gets the same projection; bad ``ymag`` is refused.
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks.raycast import AnalyticObject, Sphere, render_reference


def test_plane_has_one_view_direction(glphong_backend, glphong_make_renderer):
    kd, ks, q, e = 0.2, 0.5, 30.0, 2.0
    light = np.array([0.3, -0.2, 1.0]) / np.linalg.norm([0.3, -0.2, 1.0])
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), ymag=0.5)
    scene = glphong.Scene(camera, [glphong.DirectionalLight(-light, e)])
    scene.add(primitives.plane(0.8), glphong.Phong(kd, ks, q))  # 0.8 m square inside the 1.6 x 1 m view
    width, height = 64, 40
    frame = glphong_make_renderer(width, height, glphong_backend).render(scene, depth=True)
    r = 2 * light[2] * np.array([0.0, 0.0, 1.0]) - light
    expected = kd * light[2] * e + ks * max(r[2], 0.0) ** q * e
    covered = frame.mask
    np.testing.assert_allclose(frame.radiance[covered], expected, rtol=2e-6)
    # 0.8 m of 1.6 m across (width) and of 1.0 m down (height): 32 x 32 pixels
    assert covered.sum(axis=1).max() == 32 and covered.sum(axis=0).max() == 32
    np.testing.assert_allclose(frame.depth[covered], 3.0, rtol=1e-6)
    perspective = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.4),
                                scene.lights)
    perspective.add(primitives.plane(0.8), glphong.Phong(kd, ks, q))
    varying = glphong_make_renderer(width, height, glphong_backend).render(perspective)
    assert np.ptp(varying.radiance[varying.mask][:, 0]) > 0.01  # the highlight moves with v there


def test_sphere_against_twin_and_ray_cast(glphong_backend, glphong_make_renderer):
    camera = glphong.OrthographicCamera.look_at((0.5, 0.8, 4.0), (0.0, 0.0, 0.0), ymag=1.2)
    material = glphong.BlinnPhong(0.2, 0.5, 60.0)
    lights = [glphong.PointLight((2.0, 2.0, 3.0), 150.0)]
    scene = glphong.Scene(camera, lights, ambient=glphong.AmbientLight(0.05))
    scene.add(primitives.sphere(5, 1.0), material)
    renderer = glphong_make_renderer(96, 80, glphong_backend)
    assert glphong.verify(scene, renderer).passed
    frame = renderer.render(scene)
    exact = render_reference(camera, [AnalyticObject(Sphere((0.0, 0.0, 0.0), 1.0), material)], lights,
                             glphong.AmbientLight(0.05), 96, 80, samples_per_axis=1)
    inner = exact.interior & frame.mask
    assert inner.sum() > 2000
    diff = frame.radiance[inner] - exact.radiance[inner]
    assert np.sqrt(np.sum(diff ** 2) / np.sum(exact.radiance[inner] ** 2)) < 5e-3


def test_pyrender_projection_and_bad_input():
    camera = glphong.OrthographicCamera(0.7, znear=0.1, zfar=20.0)
    projection = camera.projection_matrix(1.5)
    np.testing.assert_allclose(projection @ [1.05, 0.7, -20.0, 1.0], [1.0, 1.0, 1.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(projection @ [0.0, 0.0, -0.1, 1.0], [0.0, 0.0, -1.0, 1.0], atol=1e-12)
    np.testing.assert_array_equal(camera.eye, [0.0, 0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match=r"ymag must be finite and in \(0"):
        glphong.OrthographicCamera(0.0)
    origins, d = camera.pixel_rays(4, 2)
    assert origins.shape == (2, 4, 3) and np.allclose(d, [0.0, 0.0, -1.0])
