"""Depth and normals alongside radiance (``Renderer.render(scene, depth=True, normals=True)``), against the
exact geometry written here: a sphere of radius R at distance D seen along -z, and a plane facing the camera.

- the plane at z = 0 seen from z = 3: depth 3 m at every covered pixel (to 1e-6), normal +z;
- the sphere: depth at each covered pixel is the ray's first hit along the viewing axis (the pixel's ray
  through its centre, from the test's own pinhole model), within the tessellation's sag (radius 1,
  icosphere level 5: 1e-3 m); normals within 0.03 of the exact sphere normal (flat-ish facets interpolate);
- uncovered pixels: depth 0 and normal 0; without the flags both are None; a bad flag is refused.
"""
import numpy as np
import pytest

import glphong
from glphong import primitives


def test_plane_depth_and_normal(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.6)
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 3.0), 10.0)])
    scene.add(primitives.plane(1.0), glphong.Lambert(0.2))
    frame = glphong_make_renderer(48, 40, glphong_backend).render(scene, depth=True, normals=True)
    covered = frame.mask
    assert 200 < covered.sum() < covered.size
    np.testing.assert_allclose(frame.depth[covered], 3.0, rtol=1e-6)
    np.testing.assert_allclose(frame.normal[covered], [[0.0, 0.0, 1.0]] * int(covered.sum()), atol=1e-6)
    assert np.all(frame.depth[~covered] == 0) and np.all(frame.normal[~covered] == 0)


def test_sphere_depth_is_the_first_hit(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.2, 4.0), (0.0, 0.0, 0.0), yfov=0.7)
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, 1.0, 3.0), 10.0)])
    scene.add(primitives.sphere(5, 1.0), glphong.Phong(0.2, 0.3, 20.0))
    width, height = 64, 56
    frame = glphong_make_renderer(width, height, glphong_backend, samples=4).render(scene, depth=True, normals=True)
    # the test's own pinhole rays through pixel centres (row 0 at the top)
    tan = np.tan(camera.yfov / 2)
    j, i = np.mgrid[0:height, 0:width]
    x = (2 * (i + 0.5) / width - 1) * tan * width / height
    y = (1 - 2 * (j + 0.5) / height) * tan
    r, u, f = camera.pose[:3, 0], camera.pose[:3, 1], -camera.pose[:3, 2]
    d = x[..., None] * r + y[..., None] * u + f
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = camera.pose[:3, 3]
    b = d @ o
    disc = b * b - (o @ o - 1.0)
    hit = disc > 0.05  # away from the silhouette, where a facet's sag grows as 1/cos
    t = -b - np.sqrt(np.maximum(disc, 0))
    point = o + t[..., None] * d
    inner = hit & frame.mask
    assert inner.sum() > 800
    np.testing.assert_allclose(frame.depth[inner], ((point - o) @ f)[inner], atol=1e-3)
    assert np.max(np.abs(frame.normal[inner] - point[inner])) < 0.03
    plain = glphong_make_renderer(8, 8, glphong_backend).render(scene)
    assert plain.depth is None and plain.normal is None
    with pytest.raises(TypeError, match="depth must be a bool"):
        glphong_make_renderer(8, 8, glphong_backend).render(scene, depth="yes")
