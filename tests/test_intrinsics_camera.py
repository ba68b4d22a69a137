"""A camera from pinhole intrinsics in OpenCV's convention (`glphong.IntrinsicsCamera`, `glphong.opencv_pose`).

Against OpenCV's projection written here (``u = fx X / Z + cx``, ``v = fy Y / Z + cy``, pixel centres at
integers, X right, Y down, Z forward; ``x_cam = R x_world + t``):

- every pixel's surface point (a tilted plane's G-buffer), projected by that formula, lands on the pixel's
  centre to 2e-3 px, with an off-centre principal point and fx != fy, at the calibrated size and at twice it;
- a plane's G-buffer positions lie on the rays `pixel_rays` gives (the same mapping the projection
  matrix encodes, written twice) to 1e-5 m;
- another aspect, a bad focal length and a non-rotation are refused naming the parameter.
"""
import numpy as np
import pytest

import glphong
from glphong import primitives

FX, FY, CX, CY, W, H = 70.0, 64.0, 41.3, 27.8, 80, 60


def _opencv_extrinsics():
    angle = 0.3
    r = np.array([[np.cos(angle), 0.0, -np.sin(angle)], [0.0, 1.0, 0.0], [np.sin(angle), 0.0, np.cos(angle)]])
    return r, np.array([0.1, -0.05, 4.0])


def _project(points, r, t):
    cam = points @ r.T + t
    return np.stack([FX * cam[:, 0] / cam[:, 2] + CX, FY * cam[:, 1] / cam[:, 2] + CY], axis=-1)


@pytest.mark.parametrize("scale", [1, 2])
def test_each_pixel_sees_what_opencv_projects_to_it(glphong_backend, glphong_make_renderer, scale):
    """Every pixel's surface point (the G-buffer of a tilted plane), projected by OpenCV's formula, lands
    on that pixel's centre: column i, row j at the calibrated size; ``(i + 0.5) / 2 - 0.5`` at twice it."""
    r, t = _opencv_extrinsics()
    camera = glphong.IntrinsicsCamera(FX, FY, CX, CY, W, H, pose=glphong.opencv_pose(r, t))
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 3.0), 10.0)])
    pose = np.eye(4)
    pose[:3, :3] = [[1.0, 0.0, 0.0], [0.0, np.cos(0.4), -np.sin(0.4)], [0.0, np.sin(0.4), np.cos(0.4)]]
    scene.add(primitives.plane(20.0), glphong.Lambert(0.2), pose=pose)
    gbuffer = glphong_make_renderer(W * scale, H * scale, glphong_backend).gbuffer(scene)
    assert gbuffer.mask.all()
    uv = _project(gbuffer.position.reshape(-1, 3).astype(np.float64), r, t).reshape(H * scale, W * scale, 2)
    rows, cols = np.mgrid[0:H * scale, 0:W * scale]
    np.testing.assert_allclose(uv[..., 0], (cols + 0.5) / scale - 0.5, atol=2e-3)
    np.testing.assert_allclose(uv[..., 1], (rows + 0.5) / scale - 0.5, atol=2e-3)


def test_pixel_rays_are_the_projection(glphong_backend, glphong_make_renderer):
    r, t = _opencv_extrinsics()
    camera = glphong.IntrinsicsCamera(FX, FY, CX, CY, W, H, pose=glphong.opencv_pose(r, t))
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 3.0), 10.0)])
    scene.add(primitives.plane(20.0), glphong.Lambert(0.2))
    gbuffer = glphong_make_renderer(W, H, glphong_backend).gbuffer(scene)
    origin, d = camera.pixel_rays(W, H)
    hit = origin + (-origin[2] / d[..., 2])[..., None] * d
    assert gbuffer.mask.all()
    np.testing.assert_allclose(gbuffer.position, hit, atol=1e-5)


def test_bad_input():
    camera = glphong.IntrinsicsCamera(FX, FY, CX, CY, W, H)
    with pytest.raises(ValueError, match=r"belongs to 80x60 images"):
        camera.projection_matrix(1.0)
    with pytest.raises(ValueError, match=r"fx must be finite and in \(0"):
        glphong.IntrinsicsCamera(0.0, FY, CX, CY, W, H)
    with pytest.raises(ValueError, match="rotation must be a"):
        glphong.opencv_pose(np.diag([1.0, 1.0, -1.0]), np.zeros(3))
    assert "IntrinsicsCamera(fx=70" in repr(camera)
