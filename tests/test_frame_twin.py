"""The float64 twin of the frame passes (glphong.checks.frame_twin) against closed forms computed here.

CPU only, no GL.  Every expected value is computed in this file from the geometry by hand: the rays from the
pinhole formula (``x = (2 xp / W - 1) tan(fov / 2) W / H``, ``y = (1 - 2 yp / H) tan(fov / 2)``), ray-plane and
ray-sphere intersections, and a brute-force ray cast of every ray against every triangle (no screen boxes).

- a unit cube (flat normals) under a rotating, translating pose: depth, distance, normal, object coordinates and
  nocs at every sample against the slab intersection, 1e-9;
- an icosphere(5) of radius 1: the facets lie between the spheres of radius ``r_in = min`` plane distance of a face
  (1 - 2.85e-4) and ``r_out = max |vertex|`` (1 + 4e-8, float32), so a ray that meets the inner sphere hits the mesh
  at ``t_out <= t <= t_in``; the unit normal there is ``p / |p|`` (the vertex normals are the positions), at an angle
  of at most ``(t_in - t_out) / r_in`` from the exact sphere's normal at ``t_out``;
- flow of a rigid motion (rotation by 0.12 rad about a tilted axis and a translation) and a moved camera, against
  the motion projected by hand, from the pixel's centre; backward flow likewise; no motion: the samples' offsets;
- an IntrinsicsCamera with its principal point off centre: every centre sample's point ``X`` (OpenCV frame) lands at
  ``u = fx X / Z + cx = i``, ``v = fy Y / Z + cy = j``, and normal_camera is ``R n`` for the OpenCV rotation ``R``;
- which object wins: overlapping quads (the nearer one, in both orders of adding), interpenetrating quads (split
  where the planes cross), coplanar quads (a tie: both ids, and both quads' nocs, allowed);
- the tie rule: parallel quads half and twice the depth buffer's resolution apart, perspective and orthographic;
- screen boxes: objects partly outside the image and a floor reaching behind the camera, perspective and
  orthographic, equal to the brute-force cast at every sample;
- front faces and normals under a mirroring pose, one- and two-sided; NaN normals under a normal map; uv of a quad;
- the bands: every sample inside, and the widening exactly the float32 rounding terms of the module where the
  samples agree; a flow at or behind the next camera's plane NaN;
- refusals: a textured alpha mask (a constant one below its cutoff hides its object), a flow without its scene or
  with another scene's meshes, uv without uvs, an unknown pass.
"""
import numpy as np
import pytest
import trimesh

import glphong
from glphong import primitives
from glphong.checks import frame_twin as ft
from glphong.scene.geometry import MeshData

W, H = 64, 48
EPS = 2.0 ** -24


def _rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def _pose(axis=(0.3, 1.0, 0.2), angle=0.7, translation=(0.1, -0.2, 0.05)):
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = _rotation(axis, angle), translation
    return pose


def _cube():
    return MeshData.from_trimesh(trimesh.creation.box(), smooth=False)


def _quad(z, half=(1.0, 1.0), centre=(0.0, 0.0), uvs=False):
    (cx, cy), (hx, hy) = centre, half
    p = [[cx - hx, cy - hy, z], [cx + hx, cy - hy, z], [cx + hx, cy + hy, z], [cx - hx, cy + hy, z]]
    return MeshData(p, [[0, 0, 1]] * 4, [[0, 1, 2], [0, 2, 3]], uvs=[[0, 0], [1, 0], [1, 1], [0, 1]] if uvs else None)


def _hand_rays(camera, width, height, offsets=ft.SAMPLE_OFFSETS):
    """Unit world directions (S, H, W, 3) of a PerspectiveCamera by the pinhole formula, and the sample positions."""
    xp = np.arange(width)[None, None, :] + offsets[:, 0, None, None]
    yp = np.arange(height)[None, :, None] + offsets[:, 1, None, None]
    xp, yp = np.broadcast_arrays(xp, yp)
    tan = np.tan(camera.yfov / 2)
    local = np.stack([(2 * xp / width - 1) * tan * width / height, (1 - 2 * yp / height) * tan, -np.ones_like(xp)], -1)
    d = local @ camera.pose[:3, :3].T
    return d / np.linalg.norm(d, axis=-1, keepdims=True), np.stack([xp, yp], -1)


def _hand_project(camera, width, height, points):
    """Image positions [px] of world points through a PerspectiveCamera, by the pinhole formula."""
    c = (points - camera.pose[:3, 3]) @ camera.pose[:3, :3]
    f = (height / 2) / np.tan(camera.yfov / 2)
    return np.stack([width / 2 + f * c[..., 0] / -c[..., 2], height / 2 - f * c[..., 1] / -c[..., 2]], -1)


def _brute_force(scene, width, height, offsets=ft.SAMPLE_OFFSETS):
    """Nearest t (inf where none) and object of every sample ray against every triangle: (S, H, W) each."""
    camera = scene.camera
    o, d = camera.sample_rays(width, height, offsets)
    d = np.moveaxis(d, 2, 0)
    o = np.moveaxis(o, 2, 0) if o.ndim > 1 else np.broadcast_to(o, d.shape)
    best, owner = np.full(d.shape[:-1], np.inf), np.full(d.shape[:-1], -1)
    forward = -camera.pose[:3, 2]
    for k, obj in enumerate(scene.objects):
        world = obj.mesh.positions.astype(float) @ obj.pose[:3, :3].T + obj.pose[:3, 3]
        for a, b, c in world[obj.mesh.indices.astype(int)]:
            n = np.cross(b - a, c - a)
            with np.errstate(divide="ignore", invalid="ignore"):
                t = ((a - o) @ n) / (d @ n)
            p = o + np.nan_to_num(t)[..., None] * d
            inside = np.ones(t.shape, bool)
            for u, v in ((a, b), (b, c), (c, a)):
                inside &= np.cross(v - u, p - u) @ n >= -1e-12 * (n @ n)
            depth = (p - camera.pose[:3, 3]) @ forward
            ok = inside & (t > 0) & (depth >= camera.znear) & (depth <= camera.zfar) & (t < best)
            best, owner = np.where(ok, t, best), np.where(ok, k, owner)
    return best, owner


def test_sample_offsets_are_the_centre_and_its_snapped_neighbours():
    assert ft.SAMPLE_OFFSETS.shape == (5, 2) and tuple(ft.SAMPLE_OFFSETS[0]) == (0.5, 0.5)
    np.testing.assert_array_equal(np.abs(ft.SAMPLE_OFFSETS[1:] - 0.5), ft.SUBPIXEL)


def test_cube_passes_are_the_slab_intersection():
    camera = glphong.PerspectiveCamera.look_at((1.6, 1.1, 2.4), (0.0, 0.0, 0.0), yfov=0.8)
    pose = _pose()
    scene = glphong.Scene(camera)
    scene.add(_cube(), glphong.Lambert(0.5), pose=pose)
    hits = ft.cast_pixels(scene, W, H)
    got = ft.twin_passes(scene, hits, ["depth", "distance", "normal", "object_coordinates", "nocs"])
    d, _ = _hand_rays(camera, W, H)
    r, t0 = pose[:3, :3], pose[:3, 3]
    o_obj, d_obj = r.T @ (camera.position - t0), d @ r  # the cube's frame (a rigid pose keeps t)
    with np.errstate(divide="ignore"):
        ta, tb = (-0.5 - o_obj) / d_obj, (0.5 - o_obj) / d_obj
    enter, leave = np.minimum(ta, tb), np.maximum(ta, tb)
    t_in, axis = enter.max(-1), enter.argmax(-1)
    second = np.sort(enter, -1)[..., 1]
    hit = t_in < leave.min(-1)
    clear = (np.abs(t_in - leave.min(-1)) > 1e-6) & (t_in - second > 1e-6)  # off the silhouette and the edges
    assert clear.sum() > 2000 and (hit & clear).sum() > 1500
    np.testing.assert_array_equal((hits.object_index >= 0)[clear], hit[clear])
    sel = hit & clear
    p_obj = o_obj + t_in[..., None] * d_obj
    n_obj = np.zeros(d.shape)
    np.put_along_axis(n_obj, axis[..., None], -np.sign(np.take_along_axis(d_obj, axis[..., None], -1)), -1)
    forward = -camera.pose[:3, 2]
    np.testing.assert_allclose(got["distance"][sel], t_in[sel], rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["depth"][sel], t_in[sel] * (d[sel] @ forward), rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["normal"][sel], n_obj[sel] @ r.T, rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["object_coordinates"][sel], p_obj[sel], rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["nocs"][sel], p_obj[sel] + 0.5, rtol=0, atol=1e-9)
    np.testing.assert_allclose(hits.position[sel], camera.position + t_in[sel, None] * d[sel], rtol=0, atol=1e-9)
    assert hits.front[sel].all() and not hits.front[~(hits.object_index >= 0)].any()
    miss = ~hit & clear
    assert (got["depth"][miss] == 0).all() and (got["normal"][miss] == 0).all()


def test_sphere_lies_within_its_tessellation_error():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.4, 3.0), (0.0, 0.0, 0.0), yfov=0.9)
    mesh = primitives.sphere(5)
    scene = glphong.Scene(camera)
    scene.add(mesh, glphong.Phong(0.3, 0.3, 20.0))
    offsets = ft.SAMPLE_OFFSETS[:1]
    hits = ft.cast_pixels(scene, W, H, offsets)
    got = ft.twin_passes(scene, hits, ["distance", "depth", "normal"])
    p, f = mesh.positions.astype(float), mesh.indices.astype(int)
    n = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    r_in = np.min(np.abs(np.sum(n * p[f[:, 0]], 1)) / np.linalg.norm(n, axis=1))
    r_out = np.max(np.linalg.norm(p, axis=1))
    assert 1 - 3e-4 < r_in < 1 and r_out < 1 + 1e-7
    d, _ = _hand_rays(camera, W, H, offsets)
    b = d @ camera.position
    c = camera.position @ camera.position

    def near_root(radius):
        disc = b * b - (c - radius ** 2)
        return -b - np.sqrt(np.maximum(disc, 0)), disc > 0

    t_out, _ = near_root(r_out)
    t_in, inner = near_root(r_in)
    assert inner.sum() > 600
    t = got["distance"]
    assert (hits.object_index[inner] == 0).all()
    assert (t[inner] >= t_out[inner] - 1e-12).all() and (t[inner] <= t_in[inner] + 1e-12).all()
    np.testing.assert_allclose(got["depth"][inner], t[inner] * (d[inner] @ -camera.pose[:3, 2]), rtol=0, atol=1e-12)
    exact = camera.position + t_out[..., None] * d
    exact /= np.linalg.norm(exact, axis=-1, keepdims=True)
    angle = np.arccos(np.clip(np.sum(got["normal"] * exact, -1), -1, 1))
    assert (angle[inner] <= (t_in - t_out)[inner] / r_in + 1e-7).all()
    point = camera.position + t[..., None] * d
    np.testing.assert_allclose(got["normal"][inner], (point / np.linalg.norm(point, axis=-1, keepdims=True))[inner],
                               rtol=0, atol=1e-9)


def test_flow_is_the_rigid_motion_projected():
    camera = glphong.PerspectiveCamera.look_at((0.5, 1.0, 3.2), (0.0, 0.0, 0.0), yfov=0.8)
    moved_camera = glphong.PerspectiveCamera.look_at((0.7, 0.9, 3.0), (0.1, 0.0, 0.0), yfov=0.8)
    motion = _pose(axis=(0.2, 1.0, 0.4), angle=0.12, translation=(0.08, -0.03, 0.05))
    mesh, pose = _cube(), _pose()
    scenes = []
    for cam, p in ((camera, pose), (moved_camera, motion @ pose), (camera, np.linalg.inv(motion) @ pose)):
        scenes.append(glphong.Scene(cam))
        scenes[-1].add(mesh, glphong.Lambert(0.5), pose=p)
    scene, nxt, prev = scenes
    hits = ft.cast_pixels(scene, W, H)
    got = ft.twin_passes(scene, hits, ["flow", "backward_flow"], next_scene=nxt, previous_scene=prev)
    _, xy = _hand_rays(camera, W, H)
    hit = hits.object_index >= 0
    assert hit.sum() > 2000
    p = hits.position[hit]
    np.testing.assert_allclose(_hand_project(camera, W, H, p), xy[hit], rtol=0, atol=1e-9)  # the hand model holds
    centre = np.floor(xy[hit]) + 0.5  # the flow is measured from the pixel's centre
    forward = _hand_project(moved_camera, W, H, p @ motion[:3, :3].T + motion[:3, 3]) - centre
    back = np.linalg.inv(motion)
    backward = _hand_project(camera, W, H, p @ back[:3, :3].T + back[:3, 3]) - centre
    np.testing.assert_allclose(got["flow"][hit], forward, rtol=0, atol=1e-8)
    np.testing.assert_allclose(got["backward_flow"][hit], backward, rtol=0, atol=1e-8)
    assert np.abs(forward).max() > 2.0 and (got["flow"][~hit] == 0).all()
    still = ft.twin_passes(scene, hits, ["flow"], next_scene=scene)["flow"]  # no motion: each sample's offset
    np.testing.assert_allclose(still[hit], (xy - np.floor(xy) - 0.5)[hit], rtol=0, atol=1e-9)
    assert np.abs(still[hit]).max() == pytest.approx(ft.SUBPIXEL)
    low, high = ft.pass_bands(scene, hits, ["flow"], next_scene=nxt)["flow"]
    spread = got["flow"].max(0) - got["flow"].min(0)
    inside = (hits.object_index >= 0).all(0)
    assert np.all(low <= got["flow"].min(0)) and np.all(high >= got["flow"].max(0))
    assert np.all((high - low - spread)[inside] > 0) and np.all((high - low - spread)[inside] < 1e-4)


def test_flow_behind_the_next_camera_is_unchecked():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene, nxt = glphong.Scene(camera), glphong.Scene(camera)
    mesh = _quad(0.0, half=(0.4, 0.4))
    scene.add(mesh, glphong.Lambert(0.5))
    nxt.add(mesh, glphong.Lambert(0.5), pose=_pose(axis=(0, 1, 0), angle=0.0, translation=(0, 0, 4.0)))
    hits = ft.cast_pixels(scene, W, H)
    flow = ft.twin_passes(scene, hits, ["flow"], next_scene=nxt)["flow"]
    hit = hits.object_index >= 0
    assert hit.sum() > 100 and np.isnan(flow[hit]).all() and (flow[~hit] == 0).all()
    low, _ = ft.pass_bands(scene, hits, ["flow"], next_scene=nxt)["flow"]
    assert np.isnan(low[hit[0]]).all()
    # on the next camera's plane (q_z = 0): NaN, though oc - r e_z lies in front of it
    away = _pose(axis=(0, 1, 0), angle=0.0, translation=(0, 0, -4))
    on_plane = glphong.Scene(glphong.PerspectiveCamera(0.8, pose=away))
    on_plane.add(mesh, glphong.Lambert(0.5), pose=away)
    assert np.isnan(ft.twin_passes(scene, hits, ["flow"], next_scene=on_plane)["flow"][hit]).all()
    low, high = ft.pass_bands(scene, hits, ["flow"], next_scene=on_plane)["flow"]
    assert np.isnan(low[hit[0]]).all() and np.isnan(high[hit[0]]).all()


def test_intrinsics_off_centre_land_where_opencv_projects():
    fx, fy, cx, cy = 58.0, 61.0, 24.3, 27.6
    centre = np.array([0.6, 1.5, 3.0])  # the camera centre in the world, looking at the origin, rolled by 0.3 rad
    z = -centre / np.linalg.norm(centre)
    x = np.cross([0.0, -1.0, 0.0], z)
    x /= np.linalg.norm(x)
    rotation = _rotation((0.0, 0.0, 1.0), 0.3) @ np.stack([x, np.cross(z, x), z])  # OpenCV: x right, y down, z ahead
    camera = glphong.IntrinsicsCamera(fx, fy, cx, cy, W, H, pose=glphong.opencv_pose(rotation, -rotation @ centre))
    scene = glphong.Scene(camera)
    scene.add(_cube(), glphong.Lambert(0.5), pose=_pose())
    hits = ft.cast_pixels(scene, W, H)
    got = ft.twin_passes(scene, hits, ["normal", "normal_camera"])
    hit = hits.object_index[0] >= 0
    assert hit.sum() > 200 and (~hit).sum() > 200
    x = (hits.position[0] - centre) @ rotation.T
    j, i = np.nonzero(hit)
    np.testing.assert_allclose(fx * x[hit, 0] / x[hit, 2] + cx, i, rtol=0, atol=1e-9)
    np.testing.assert_allclose(fy * x[hit, 1] / x[hit, 2] + cy, j, rtol=0, atol=1e-9)
    np.testing.assert_allclose(got["normal_camera"][0][hit], got["normal"][0][hit] @ rotation.T, rtol=0, atol=1e-12)
    assert (np.sum(got["normal_camera"][0][hit] * x[hit], -1) < 0).all()  # the faces seen face the camera


def _which(scene, hits):
    """The name of the object each sample shows ('' for none)."""
    names = np.array([obj.name for obj in scene.objects] + [""])
    return names[hits.object_index]


@pytest.mark.parametrize("order", [1, -1])
def test_the_nearer_of_overlapping_quads_wins_whatever_the_order(order):
    camera = glphong.PerspectiveCamera(0.9, znear=0.1, zfar=20.0)
    scene = glphong.Scene(camera)
    quads = [("near", _quad(-3.0, half=(0.5, 0.4), centre=(0.3, 0.1))), ("far", _quad(-6.0, half=(5.0, 5.0)))]
    for name, mesh in quads[::order]:
        scene.add(mesh, glphong.Lambert(0.5), name=name)
    hits = ft.cast_pixels(scene, W, H)
    d, _ = _hand_rays(camera, W, H)
    near = -3.0 * d / d[..., 2:]
    inside = (np.abs(near[..., 0] - 0.3) < 0.5) & (np.abs(near[..., 1] - 0.1) < 0.4)
    shown = _which(scene, hits)
    assert inside.sum() > 100 and (shown == "far").sum() > 100
    assert (shown[inside] == "near").all() and (shown[~inside] == "far").all()
    ids = ft.twin_passes(scene, hits, ["instance"])["instance"]
    np.testing.assert_array_equal(ids, np.where(shown == "near", 1 if order == 1 else 2, 2 if order == 1 else 1))


@pytest.mark.parametrize("order", [1, -1])
def test_interpenetrating_quads_split_where_they_cross(order):
    camera = glphong.PerspectiveCamera(0.9)
    scene = glphong.Scene(camera)
    meshes = {}
    for name, slope in (("rising", 0.5), ("falling", -0.5)):
        p = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
        p[:, 2] = -4.0 + slope * p[:, 0]
        meshes[name] = MeshData(p, [[0, 0, 1]] * 4, [[0, 1, 2], [0, 2, 3]])
    for name in list(meshes)[::order]:
        scene.add(meshes[name], glphong.Lambert(0.5), name=name)
    hits = ft.cast_pixels(scene, W, H)
    d, _ = _hand_rays(camera, W, H)
    t = {name: -4.0 / (d[..., 2] - slope * d[..., 0]) for name, slope in (("rising", 0.5), ("falling", -0.5))}
    x = {name: t[name] * d[..., 0] for name in t}
    both = (np.abs(x["rising"]) < 0.99) & (np.abs(x["falling"]) < 0.99) & (np.abs(d[..., 1] / d[..., 2] * 4.5) < 0.9)
    clear = both & (np.abs(t["rising"] - t["falling"]) > 1e-6)
    expected = np.where(t["rising"] < t["falling"], "rising", "falling")
    shown = _which(scene, hits)
    assert clear.sum() > 1000 and min((expected[clear] == name).sum() for name in meshes) > 300
    np.testing.assert_array_equal(shown[clear], expected[clear])
    assert (shown[clear & (d[..., 0] > 0)] == "rising").all()  # split at x = 0, the crossing


@pytest.mark.parametrize("order", [1, -1])
def test_coplanar_quads_are_ties_and_the_band_allows_both(order):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera)
    for name, centre in (("left", -0.3), ("right", 0.3))[::order]:
        scene.add(_quad(0.0, half=(0.6, 0.6), centre=(centre, 0.0)), glphong.Lambert(0.5), name=name)
    hits = ft.cast_pixels(scene, W, H)
    d, _ = _hand_rays(camera, W, H)
    p = camera.position + (-3.0 / d[..., 2:]) * d
    overlap = (np.abs(p[..., 0]) < 0.29) & (np.abs(p[..., 1]) < 0.59)
    alone = (np.abs(p[..., 0]) > 0.31) & (np.abs(p[..., 0]) < 0.89) & (np.abs(p[..., 1]) < 0.59)
    assert overlap.sum() > 100 and alone.sum() > 100
    tie = hits.tie_object_index >= 0
    assert tie[overlap].all() and not tie[alone].any()
    assert (np.sort(np.stack([hits.object_index, hits.tie_object_index]), 0)[:, overlap] == [[0], [1]]).all()
    bands = ft.pass_bands(scene, hits, ["instance", "depth", "normal", "nocs"])
    allowed = bands["instance"]
    both = overlap.all(0)
    assert allowed.shape[-1] >= 2 and (np.sort(allowed[both][:, :2], -1) == [1, 2]).all()
    low, high = bands["depth"]
    np.testing.assert_allclose((high - low)[both], 2 * 32 * EPS * (0.9 + 3.0), rtol=1e-6)  # depth 3 everywhere
    low, high = bands["normal"]
    np.testing.assert_array_equal((high - low)[both], 2 * 16 * EPS)  # one normal, (0, 0, 1), in both quads
    nocs = {name: (p[..., 0] - centre + 0.6) / 1.2 for name, centre in (("left", -0.3), ("right", 0.3))}
    low, high = bands["nocs"]  # both quads' nocs, the nearest's (the first added) and the tie's
    assert (nocs["left"] > nocs["right"] + 0.4).all()
    assert (low[..., 0][both] <= nocs["right"].min(0)[both] - 1e-7).all()
    assert (high[..., 0][both] >= nocs["left"].max(0)[both] + 1e-7).all()
    assert (high - low)[..., 0][both].max() < 0.6
    empty, single = (hits.object_index < 0).all(0), alone.all(0)
    assert empty.sum() > 100 and (allowed[empty][:, 0] == 0).all() and (allowed[empty][:, 1:] == -1).all()
    assert single.sum() > 100 and ((allowed[single] > 0).sum(-1) == 1).all() and (allowed[single] == 0).sum() == 0


@pytest.mark.parametrize("kind", ["perspective", "orthographic"])
def test_a_tie_is_within_the_depth_buffer_resolution(kind):
    n, f, z = 0.1, 100.0, 5.0
    camera = glphong.PerspectiveCamera(0.8, znear=n, zfar=f) if kind == "perspective" else \
        glphong.OrthographicCamera(2.0, znear=n, zfar=f)
    resolution = 8 * EPS * (f - n) * (z * z / (f * n) if kind == "perspective" else 1.0)
    assert ft.depth_tie(camera, z, z + resolution * (1 - 1e-9))
    assert not ft.depth_tie(camera, z, z + resolution * (1 + 1e-9))
    for gap, tied in ((0.5 * resolution, True), (2.0 * resolution, False)):
        scene = glphong.Scene(camera)
        scene.add(_quad(-z), glphong.Lambert(0.5))
        scene.add(_quad(-z - gap), glphong.Lambert(0.5))
        hits = ft.cast_pixels(scene, 16, 16)
        covered = hits.object_index >= 0
        assert covered.sum() > 200 and (hits.object_index[covered] == 0).all()
        assert ((hits.tie_object_index[covered] == 1) == tied).all()


@pytest.mark.parametrize("kind", ["perspective", "orthographic"])
def test_screen_boxes_miss_nothing_the_brute_force_cast_finds(kind):
    eye, target = (0.4, 0.5, 2.2), (0.9, 0.2, 0.0)
    camera = (glphong.PerspectiveCamera.look_at(eye, target, yfov=0.9, znear=0.2, zfar=8.0) if kind == "perspective"
              else glphong.OrthographicCamera.look_at(eye, target, ymag=1.2, znear=0.2, zfar=8.0))
    scene = glphong.Scene(camera)
    floor = MeshData([[-6, -0.6, -6], [6, -0.6, -6], [6, -0.6, 9], [-6, -0.6, 9]], [[0, 1, 0]] * 4,
                     [[0, 2, 1], [0, 3, 2]])  # reaches behind the camera, past znear and zfar
    scene.add(floor, glphong.Lambert(0.5))
    scene.add(primitives.sphere(2, 0.7), glphong.Lambert(0.5), pose=_pose(translation=(2.2, 0.3, -0.5)))
    scene.add(_cube(), glphong.Lambert(0.5), pose=_pose(translation=(-0.3, 0.1, 0.3)))
    hits = ft.cast_pixels(scene, 40, 30)
    t, owner = _brute_force(scene, 40, 30)
    assert (owner == 0).any() and (owner < 0).any()
    assert (owner[..., -1] == 1).any() and (owner[..., 0] == 2).any()  # the sphere and the cube cross the image's sides
    near_edge = ~np.isfinite(t) & (hits.object_index >= 0)  # rays grazing an edge may go either way
    assert near_edge.sum() <= 2
    found = hits.object_index >= 0
    np.testing.assert_array_equal(found | near_edge, np.isfinite(t) | near_edge)
    sure = found & np.isfinite(t)
    np.testing.assert_allclose(hits.t[sure], t[sure], rtol=1e-12, atol=1e-12)
    same_t = np.abs(hits.t - np.where(np.isfinite(t), t, 0)) < 1e-9
    assert (hits.object_index[sure & ~same_t] == owner[sure & ~same_t]).all()


def test_mirroring_pose_reverses_front_and_two_sided_flips_the_normal():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0), yfov=0.8)
    results = {}
    for mirror in (False, True):
        for two_sided in (True, False):
            scene = glphong.Scene(camera)
            scene.add(_quad(0.0, half=(0.5, 0.5)), glphong.Lambert(0.5, two_sided=two_sided),
                      pose=np.diag([1.0, 1.0, -1.0 if mirror else 1.0, 1.0]))
            hits = ft.cast_pixels(scene, W, H)
            hit = hits.object_index >= 0
            results[mirror, two_sided] = hits.front[hit], ft.twin_passes(scene, hits, ["normal"])["normal"][hit]
    assert results[False, True][0].all() and not results[True, True][0].any()
    np.testing.assert_array_equal(results[False, True][1], [[0, 0, 1]] * len(results[False, True][1]))
    np.testing.assert_array_equal(results[True, True][1], [[0, 0, 1]] * len(results[True, True][1]))  # flipped back
    np.testing.assert_array_equal(results[True, False][1], [[0, 0, -1]] * len(results[True, False][1]))


def test_a_normal_map_leaves_the_normals_unchecked():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera)
    mapped = glphong.NormalMap(np.full((2, 2, 3), (128, 128, 255), np.uint8))
    scene.add(_quad(0.0, half=(0.3, 0.3), uvs=True), glphong.Lambert(0.5, normal_map=mapped))
    scene.add(_quad(-1.0, half=(3.0, 3.0)), glphong.Lambert(0.5))
    hits = ft.cast_pixels(scene, W, H)
    got = ft.twin_passes(scene, hits, ["normal", "normal_camera"])
    low, high = ft.pass_bands(scene, hits, ["normal"])["normal"]
    mapped_hit, plain_hit = hits.object_index == 0, hits.object_index == 1
    assert mapped_hit.sum() > 100 and plain_hit.sum() > 100
    for name in ("normal", "normal_camera"):
        assert np.isnan(got[name][mapped_hit]).all() and np.isfinite(got[name][plain_hit]).all()
    assert np.isnan(low[mapped_hit.any(0)]).all() and np.isfinite(high[plain_hit.all(0)]).all()


def test_bands_hold_every_sample_and_the_rounding():
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.8, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera)
    scene.add(primitives.sphere(3), glphong.Lambert(0.5))
    scene.add(_quad(-1.0, half=(3.0, 3.0), uvs=True), glphong.Lambert(0.5), pose=_pose(axis=(1, 0, 0), angle=-1.2,
                                                                                        translation=(0, 0, 0)))
    names = ["depth", "distance", "normal", "normal_camera", "object_coordinates", "nocs", "category"]
    hits = ft.cast_pixels(scene, W, H)
    values = ft.twin_passes(scene, hits, names)
    bands = ft.pass_bands(scene, hits, names)
    for name in names[:-1]:
        low, high = bands[name]
        assert np.all(low <= values[name].min(0)) and np.all(high >= values[name].max(0)), name
    interior = (hits.object_index == 0).all(0)
    low, high = bands["depth"]
    term = 32 * EPS * (np.max(np.abs(primitives.sphere(3).positions)) + np.linalg.norm(camera.position))
    spread = values["depth"][:, interior].max(0) - values["depth"][:, interior].min(0)
    np.testing.assert_allclose((high - low)[interior], spread + 2 * term, rtol=1e-9)
    low, high = bands["object_coordinates"]
    spread = np.ptp(values["object_coordinates"][:, interior], axis=0)
    term = 8 * EPS * np.max(np.abs(primitives.sphere(3).positions))
    np.testing.assert_allclose((high - low)[interior] - spread, 2 * term, rtol=1e-6)
    assert (bands["category"] >= 0).sum(-1).max() == 1  # every object's category is 0, a miss too


def test_uv_is_the_interpolated_texture_coordinate_and_needs_uvs():
    camera = glphong.PerspectiveCamera.look_at((0.1, -0.2, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera)
    scene.add(_quad(0.0, half=(0.8, 0.5), centre=(0.1, 0.05), uvs=True), glphong.Lambert(0.5))
    hits = ft.cast_pixels(scene, W, H)
    uv = ft.twin_passes(scene, hits, ["uv"])["uv"]
    hit = hits.object_index >= 0
    p = hits.position[hit]
    (x0, y0), (x1, y1) = np.float32([[0.1 - 0.8, 0.05 - 0.5], [0.1 + 0.8, 0.05 + 0.5]]).astype(float)  # as stored
    assert hit.sum() > 1000
    np.testing.assert_allclose(uv[hit], np.stack([(p[:, 0] - x0) / (x1 - x0), (p[:, 1] - y0) / (y1 - y0)], -1),
                               rtol=0, atol=1e-12)
    low, high = ft.pass_bands(scene, hits, ["uv"])["uv"]
    full = hit.all(0)
    assert np.all(low <= uv.min(0)) and np.all(high >= uv.max(0))
    np.testing.assert_allclose((high - low - (uv.max(0) - uv.min(0)))[full], 2 * 8 * EPS, rtol=1e-6)  # max|uv| = 1
    scene.add(_quad(-1.0, half=(3.0, 3.0)), glphong.Lambert(0.5), name="bare")
    with pytest.raises(ValueError, match="'bare' has no uvs"):
        ft.twin_passes(scene, ft.cast_pixels(scene, W, H), ["uv"])


def test_alpha_masks_constant_skipped_textured_refused():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera)
    scene.add(_quad(0.0, half=(2.0, 2.0)), glphong.Lambert(0.5), name="back")
    scene.add(_quad(1.0, half=(0.5, 0.5)), glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, 0.49)), name="clear")
    scene.add(_quad(1.5, half=(0.2, 0.2)), glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, 0.5)), name="kept")
    shown = _which(scene, ft.cast_pixels(scene, W, H))
    assert not (shown == "clear").any() and (shown == "kept").sum() > 50
    texture = glphong.Texture(np.array([[255, 0]], np.uint8), 1.0, srgb=False, channel="r")
    scene.add(_quad(0.5, uvs=True), glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(0.5, texture)), name="lace")
    with pytest.raises(ValueError, match="'lace'.*does not check textured alpha masks"):
        ft.cast_pixels(scene, W, H)


def test_flow_needs_its_scene_and_the_same_meshes():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene, other = glphong.Scene(camera), glphong.Scene(camera)
    scene.add(_cube(), glphong.Lambert(0.5))
    other.add(_cube(), glphong.Lambert(0.5))  # an equal mesh, but another object
    hits = ft.cast_pixels(scene, 8, 8)
    with pytest.raises(ValueError, match="'flow' pass needs next_scene"):
        ft.twin_passes(scene, hits, ["depth", "flow"])
    with pytest.raises(ValueError, match="'backward_flow' pass needs previous_scene"):
        ft.pass_bands(scene, hits, ["backward_flow"], next_scene=scene)
    with pytest.raises(ValueError, match="'flow' pass needs next_scene to hold the same objects"):
        ft.twin_passes(scene, hits, ["flow"], next_scene=other)
    with pytest.raises(ValueError, match="unknown passes"):
        ft.twin_passes(scene, hits, ["albedo"])
