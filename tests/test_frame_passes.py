"""The frame passes of `glphong.Renderer.render` (`glphong.gpu.passes`) against closed forms written here.

- A sphere: 'distance' and 'depth' against the analytic sphere's hit along each pixel's ray, within the tessellation's
  sagitta; 'normal' against the analytic normal; 'normal_camera' is OpenCV's frame of it.
- An OpenCV camera with its principal point off centre: every pixel's object point projects, by ``u = fx X / Z + cx``,
  onto that pixel's centre; 'flow' of a cube that rotates and translates against the rigid motion projected by hand.
- Ids, categories, 'nocs', a pass-only frame, an object partly outside the image; the errors: an unknown pass, 'uv'
  on a mesh without uvs, flow without or with a non-corresponding other scene, bad ids.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.gpu.passes import PASSES
from glphong.scene.geometry import MeshData

FX, FY, CX, CY, W, H = 70.0, 64.0, 41.3, 27.8, 80, 60
ALL = tuple(p for p in PASSES if p not in ("flow", "backward_flow"))


def _sphere_scene(camera, radius=0.8):
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(primitives.sphere(5, radius), glphong.Phong(0.2, 0.4, 20.0), instance_id=7, category=3)
    return scene


def _ray_sphere(origin, directions, radius):
    """Nearest positive hit ``t`` of unit rays with the sphere of ``radius`` at the origin (NaN on a miss)."""
    b = directions @ origin
    c = origin @ origin - radius ** 2
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        return np.where(disc >= 0, -b - np.sqrt(disc), np.nan)


def test_sphere_distance_depth_and_normals_are_the_analytic_ones(glphong_backend, glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.4, 0.3, 3.0), (0.0, 0.0, 0.0), yfov=0.7)
    scene = _sphere_scene(camera)
    frame = glphong_make_renderer(W, H, glphong_backend).render(scene, passes=ALL)
    origin, directions = camera.pixel_rays(W, H)
    t = _ray_sphere(origin, directions, 0.8)
    hit = frame.instance == 7
    point = origin + t[..., None] * directions
    normal = point / 0.8
    facing = -np.sum(normal * directions, axis=-1)  # the cosine of the ray with the normal
    inner = hit & (facing > 0.3)  # the silhouette apart: there the tessellated and the true sphere part
    mesh = scene.objects[0].mesh
    centroids = mesh.positions[mesh.indices.astype(int)].astype(np.float64).mean(axis=1)
    sagitta = 0.8 - np.min(np.linalg.norm(centroids, axis=1))  # the facets' deepest point below the sphere
    assert inner.sum() > 1000 and sagitta < 2e-3
    assert np.abs(frame.distance[inner] - t[inner]).max() <= sagitta / 0.3
    forward = -camera.pose[:3, 2]
    assert np.abs(frame.depth[inner] - (t * (directions @ forward))[inner]).max() <= sagitta / 0.3
    assert np.all(frame.distance[~hit] == 0) and np.all(frame.depth[~hit] == 0)
    cos = np.sum(frame.normal[inner] * normal[inner], axis=-1)
    assert cos.min() > np.cos(0.05)  # the interpolated vertex normals of a 20480-face sphere: within 0.05 rad
    r_cv = np.diag([1.0, -1.0, -1.0]) @ camera.pose[:3, :3].T
    assert np.allclose(frame.normal_camera, frame.normal @ r_cv.T, atol=2e-7)
    assert np.all(frame.normal_camera[inner][:, 2] < 0)  # facing the camera: toward -z in OpenCV's frame
    assert np.array_equal(np.unique(frame.category), [0, 3]) and np.array_equal(frame.category == 3, hit)
    assert frame.instance.dtype == np.uint32 and frame.category.dtype == np.uint32
    lo, hi = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    assert np.allclose(frame.nocs[hit], (frame.object_coordinates[hit] - lo) / (hi - lo), atol=1e-6)
    assert frame.nocs[hit].min() >= 0 and frame.nocs[hit].max() <= 1
    assert np.allclose(frame.uv[~hit], 0) and frame.uv[hit].max() <= 1


def _opencv_camera(scale=1):
    angle = 0.3
    r = np.array([[np.cos(angle), 0.0, -np.sin(angle)], [0.0, 1.0, 0.0], [np.sin(angle), 0.0, np.cos(angle)]])
    t = np.array([0.1, -0.05, 4.0])
    return glphong.IntrinsicsCamera(FX, FY, CX, CY, W, H, pose=glphong.opencv_pose(r, t)), r, t


def _project(points, r, t):
    cam = points @ r.T + t
    return np.stack([FX * cam[..., 0] / cam[..., 2] + CX, FY * cam[..., 1] / cam[..., 2] + CY], axis=-1)


def _cube_pose(angle, shift):  # a turn of ``angle`` [rad] about +y, then ``shift`` [m]
    pose = trimesh.transformations.rotation_matrix(angle, (0.0, 1.0, 0.0))
    pose[:3, 3] = shift
    return pose


def _cube_scene(camera, pose):
    scene = glphong.Scene(camera, [glphong.PointLight((0.0, 0.0, 3.0), 10.0)])
    scene.add(MeshData.from_trimesh(trimesh.creation.box((1.0, 1.2, 0.8)), smooth=False), glphong.Lambert(0.5),
              pose=pose, instance_id=9)
    return scene


def test_every_pass_agrees_with_opencv_projection_off_centre(glphong_backend, glphong_make_renderer):
    """Each covered pixel's object point, moved by the pose and projected by OpenCV's formula, is that pixel's centre;
    the flow of a cube rotating by 0.2 rad and translating is the rigid motion projected by hand (Kubric's convention:
    pure projection), forward and backward."""
    camera, r, t = _opencv_camera()
    now, later, before = _cube_pose(0.5, (0.0, 0.0, 0.2)), _cube_pose(0.7, (0.15, -0.1, 0.0)), _cube_pose(0.4, (-0.1, 0.0, 0.3))
    scene = _cube_scene(camera, now)
    mesh = scene.objects[0].mesh
    other_camera, r2, t2 = _opencv_camera()
    next_scene, previous_scene = glphong.Scene(other_camera), glphong.Scene(other_camera)
    next_scene.add(mesh, glphong.Lambert(0.5), pose=later, instance_id=9)
    previous_scene.add(mesh, glphong.Lambert(0.5), pose=before, instance_id=9)
    frame = glphong_make_renderer(W, H, glphong_backend).render(
        scene, passes=("instance", "object_coordinates", "flow", "backward_flow", "depth"), next_scene=next_scene,
        previous_scene=previous_scene)
    hit = frame.instance == 9
    assert 300 < hit.sum() < W * H and frame.radiance is None and frame.mask.sum() == hit.sum()
    obj = np.concatenate([frame.object_coordinates.astype(np.float64), np.ones((H, W, 1))], axis=-1)
    rows, cols = np.mgrid[0:H, 0:W]
    uv = _project((obj @ now.T)[..., :3], r, t)
    assert np.abs(uv[..., 0] - cols)[hit].max() < 2e-3 and np.abs(uv[..., 1] - rows)[hit].max() < 2e-3
    for flow, pose in ((frame.flow, later), (frame.backward_flow, before)):
        there = _project((obj @ pose.T)[..., :3], r2, t2)
        expected = np.stack([there[..., 0] - cols, there[..., 1] - rows], axis=-1)  # OpenCV's centres are integers
        assert np.abs(flow - expected)[hit].max() < 2e-3
        assert np.abs(flow[hit]).max() > 1.0 and np.all(flow[~hit] == 0)


def test_flow_behind_the_other_camera_is_nan(glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene = _cube_scene(camera, np.eye(4))
    behind = glphong.Scene(camera)
    behind.add(scene.objects[0].mesh, glphong.Lambert(0.5), pose=_cube_pose(0.0, (0.0, 0.0, 5.0)))
    frame = glphong_make_renderer(32, 32, "egl").render(scene, passes=("instance", "flow"), next_scene=behind)
    hit = frame.instance > 0
    assert hit.any() and np.all(np.isnan(frame.flow[hit])) and np.all(frame.flow[~hit] == 0)


def test_an_object_partly_outside_the_image(glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.6)
    scene = _cube_scene(camera, _cube_pose(0.3, (0.7, 0.2, 0.0)))
    frame = glphong_make_renderer(48, 32, "egl").render(scene, passes=("instance", "depth", "nocs"))
    hit = frame.instance == 9
    assert hit[:, -1].any() and not hit[:, 0].any()  # cut by the right edge
    assert frame.nocs[hit].min() >= 0 and frame.nocs[hit].max() <= 1 and np.all(frame.depth[hit] > 2)


def test_ids_defaults_and_flat_boxes(glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera)
    scene.add(primitives.plane(1.0, 1), glphong.Lambert(0.5), category=4)  # instance 1 by default; flat in z
    pose = np.eye(4)
    pose[:3, 3] = (0.0, 0.0, 0.5)
    scene.add(primitives.sphere(2, 0.2), glphong.Lambert(0.5), pose=pose, instance_id=2 ** 32 - 1)
    frame = glphong_make_renderer(32, 32, "egl").render(scene, passes=("instance", "category", "nocs"))
    assert set(np.unique(frame.instance)) == {0, 1, 2 ** 32 - 1}
    assert set(np.unique(frame.category[frame.instance == 1])) == {4}
    assert np.all(frame.nocs[frame.instance == 1][:, 2] == 0.5)  # the plane's box is flat along z
    with pytest.raises(ValueError, match="instance_id 4294967295 is already object 'object1'"):
        scene.add(primitives.plane(1.0, 1), glphong.Lambert(0.5), instance_id=2 ** 32 - 1)
    with pytest.raises(ValueError, match=r"instance_id must be in \[1, 4294967295\]"):
        scene.add(primitives.plane(1.0, 1), glphong.Lambert(0.5), instance_id=0)
    with pytest.raises(TypeError, match="category must be an integer"):
        scene.add(primitives.plane(1.0, 1), glphong.Lambert(0.5), category=1.5)


def test_passes_it_cannot_give_are_errors_naming_the_fix(glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene = _cube_scene(camera, np.eye(4))
    renderer = glphong_make_renderer(16, 16, "egl")
    with pytest.raises(ValueError, match="unknown pass 'segmentation'; the passes are radiance, depth"):
        renderer.render(scene, passes=("segmentation",))
    with pytest.raises(ValueError, match="'uv' pass needs texture coordinates .* object 'object0' has none"):
        renderer.render(scene, passes=("uv",))
    with pytest.raises(ValueError, match="'flow' pass needs next_scene"):
        renderer.render(scene, passes=("flow",))
    with pytest.raises(ValueError, match="previous_scene is given but the 'backward_flow' pass is not asked for"):
        renderer.render(scene, previous_scene=scene)
    other = glphong.Scene(camera)
    other.add(trimesh.creation.box(), glphong.Lambert(0.5))
    with pytest.raises(ValueError, match="another mesh"):
        renderer.render(scene, passes=("flow",), next_scene=other)
    with pytest.raises(TypeError, match="sequence of pass names"):
        renderer.render(scene, passes=(1,))
    frame = renderer.render(scene, passes=("depth",))
    with pytest.raises(ValueError, match="holds no radiance"):
        frame.save_png("x.png")
    assert frame.passes == ("depth",) and frame._repr_png_() is None


def test_the_depth_flag_and_the_depth_pass_agree(glphong_make_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.4, 0.3, 3.0), (0.0, 0.0, 0.0), yfov=0.7)
    scene = _sphere_scene(camera)
    renderer = glphong_make_renderer(W, H, "egl")
    a = renderer.render(scene, depth=True, normals=True)
    b = renderer.render(scene, passes=("radiance", "depth", "normal", "object_coordinates"))
    assert a.passes == ("radiance", "depth", "normal")
    assert np.array_equal(a.depth, b.depth) and np.array_equal(a.normal, b.normal)
    assert np.array_equal(a.radiance, b.radiance)


def test_one_draw_gives_the_radiance_and_the_planes_of_the_separate_draws(glphong_backend, glphong_make_renderer):
    """With one sample per pixel the passes come from the shading draw itself (multiple render targets): its radiance
    is bit-identical to a radiance-only render, and every pass to the one derived from the separate G-buffer draw
    (the path a multisampled renderer takes)."""
    from glphong.gpu.passes import derive_passes, gbuffer_planes
    camera = glphong.PerspectiveCamera.look_at((0.4, 0.3, 3.0), (0.0, 0.0, 0.0), yfov=0.7)
    scene = _sphere_scene(camera)
    plane = primitives.plane(1.5)
    scene.add(plane, glphong.Lambert(0.4), pose=_cube_pose(0.3, (0.2, -0.4, -0.5)),
              instance_id=3, category=1)
    later = _sphere_scene(camera)
    later.add(plane, glphong.Lambert(0.4), pose=_cube_pose(0.35, (0.25, -0.4, -0.5)), instance_id=3, category=1)
    renderer = glphong_make_renderer(W, H, glphong_backend)
    names = tuple(p for p in PASSES if p not in ("backward_flow", "matte"))  # the matte: a draw of its own
    frame = renderer.render(scene, passes=names, next_scene=later)
    assert renderer.program_key(scene, scene.objects[0], "radiance", ("position", "normal", "uv")).pass_planes
    assert np.array_equal(frame.radiance, renderer.render(scene).radiance)
    geometry = [n for n in names if n != "radiance"]
    separate = derive_passes(scene, renderer.gbuffer(scene, gbuffer_planes(geometry)), geometry, next_scene=later)
    for name in geometry:
        assert np.array_equal(getattr(frame, name), separate[name], equal_nan=True), name
    assert frame.instance.max() == 7 and (frame.instance == 3).sum() > 100
