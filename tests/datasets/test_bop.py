"""`glphong.datasets.bop.write_bop`: a render written as a BOP image, read back the way the BOP toolkit reads it
(github.com/thodan/bop_toolkit) and checked against independent truth: the frame's own passes, each object rendered
alone, projections of known model points, a second render at another pose.

The readers below restate the toolkit's: ``bop_toolkit_lib/inout.py`` ``load_json(path, keys_to_int=True)``,
``load_depth`` (``imageio.imread(path).astype(np.float32)``, then ``* depth_scale`` for mm, as
``scripts/calc_gt_info.py`` does), ``load_im`` for the masks; ``bop_toolkit_lib/misc.py`` ``calc_2d_bbox`` and
``project_pts``.  imageio decodes a PNG with Pillow (its pillow plugin: a 16-bit greyscale file as uint16, an 8-bit
one as uint8); the tests call Pillow directly, a declared dependency, where imageio is not.
"""
import hashlib
import json
import os

import numpy as np
import pytest
import trimesh
from PIL import Image

import glphong
from glphong import primitives
from glphong.core.filesafety import SceneFileError
from glphong.datasets.bop import bop_camera_matrix, bop_world_to_camera, write_bop
from glphong.scene.geometry import MeshData

W, H = 64, 48
SPHERE = primitives.sphere(3, 0.5)
SMALL = primitives.sphere(3, 0.3)
HALF = np.array([0.3, 0.25, 0.2])  # the box's half extents [m]
BOX = MeshData.from_trimesh(trimesh.creation.box(2 * HALF), smooth=False)


# -- the toolkit's readers, restated ----------------------------------------------------------------------------------

def load_json(path, keys_to_int=False):
    """bop_toolkit_lib/inout.py load_json."""
    def convert_keys_to_int(x):
        return {int(k) if k.lstrip("-").isdigit() else k: v for k, v in x.items()}

    with open(path) as f:
        if keys_to_int:
            return json.load(f, object_hook=convert_keys_to_int)
        return json.load(f)


def imread(path):
    """imageio.imread of a PNG: Pillow's decoding as an array (16-bit greyscale as uint16)."""
    with Image.open(path) as im:
        assert im.format == "PNG"
        if im.mode in ("I;16", "I;16B", "I"):
            values = np.asarray(im)
            assert values.min() >= 0 and values.max() <= 65535
            return values.astype(np.uint16)
        return np.asarray(im).copy()


def png_bit_depth(path):
    """The bit depth and colour type in the PNG's IHDR (bytes 24 and 25 of the file)."""
    with open(path, "rb") as handle:
        head = handle.read(26)
    return head[24], head[25]


def load_depth(path):
    """bop_toolkit_lib/inout.py load_depth (the caller multiplies by depth_scale)."""
    return imread(path).astype(np.float32)


def load_mask(path):
    """A mask as the toolkit's load_im gives it, checked 8-bit 0/255, as a bool image."""
    assert png_bit_depth(path) == (8, 0)  # 8-bit greyscale
    im = imread(path)
    assert im.dtype == np.uint8 and im.shape == (H, W), (im.dtype, im.shape)
    assert set(np.unique(im)) <= {0, 255}
    return im == 255


def save_json_text(content):
    """The text bop_toolkit_lib/inout.py save_json writes for a dict (keys sorted, one a line)."""
    lines = []
    for elem_id, (k, v) in enumerate(sorted(content.items(), key=lambda x: x[0])):
        comma = "," if elem_id != len(content) - 1 else ""
        lines.append('  "{}": {}'.format(k, json.dumps(v, sort_keys=True)) + comma)
    return "{\n" + "".join(line + "\n" for line in lines) + "}"


def calc_2d_bbox(xs, ys):
    """bop_toolkit_lib/misc.py calc_2d_bbox (clip=False)."""
    return [int(xs.min()), int(ys.min()), int(xs.max() - xs.min()), int(ys.max() - ys.min())]


def project_pts(pts, K, R, t):
    """bop_toolkit_lib/misc.py project_pts."""
    P = K.dot(np.hstack((R, np.reshape(t, (3, 1)))))
    pts_h = np.hstack((pts, np.ones((pts.shape[0], 1))))
    pts_im = P.dot(pts_h.T)
    pts_im /= pts_im[2, :]
    return pts_im[:2, :].T


# -- scenes -----------------------------------------------------------------------------------------------------------

def _pose(shift, angle=0.0):
    c, s = np.cos(angle), np.sin(angle)
    pose = np.eye(4)
    pose[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    pose[:3, 3] = shift
    return pose


def _camera(eye=(0.2, 0.3, 3.0)):
    pose = glphong.PerspectiveCamera.look_at(eye, (0.0, 0.0, 0.0)).pose
    return glphong.IntrinsicsCamera(58.0, 60.0, 30.7, 24.2, W, H, pose=pose)


def _scene(camera=None, shift=0.0, objects=3):
    """A sphere (instance 3) half hidden by a box in front of it (instance 5), and a small sphere cut off by the
    image's right edge (instance 8)."""
    scene = glphong.Scene(camera or _camera(), [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(SPHERE, glphong.Phong(0.3, 0.4, 20.0), pose=_pose((-0.3 + shift, 0.0, 0.0), 0.7), instance_id=3)
    if objects > 1:
        scene.add(BOX, glphong.Lambert(0.5), pose=_pose((0.1, 0.05, 0.9), -0.4), instance_id=5)
    if objects > 2:
        scene.add(SMALL, glphong.Lambert(0.6), pose=_pose((1.35, -0.1, 0.0), 1.1), instance_id=8)
    return scene


OBJ_IDS = {3: 1, 5: 2, 8: 1}


def _snapshot(folder):
    """Every path under ``folder`` with its bytes' hash (a folder maps to None)."""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            out[os.path.relpath(os.path.join(root, name), folder)] = None
        for name in files:
            with open(os.path.join(root, name), "rb") as handle:
                out[os.path.relpath(os.path.join(root, name), folder)] = hashlib.sha256(handle.read()).hexdigest()
    return out


# -- tests ------------------------------------------------------------------------------------------------------------

def test_an_image_reads_back_as_the_truth(glphong_backend, glphong_make_renderer, tmp_path):
    renderer = glphong_make_renderer(W, H, glphong_backend)
    scene = _scene()
    written = write_bop(tmp_path, scene, renderer, scene_id=4, im_id=2, obj_ids=OBJ_IDS)
    frame = renderer.render(scene, passes=("radiance", "depth", "instance"))
    base = tmp_path / "000004"
    names = ["rgb/000002.png", "depth/000002.png", "scene_camera.json", "scene_gt.json", "scene_gt_info.json"]
    names += [f"{kind}/000002_{k:06d}.png" for kind in ("mask", "mask_visib") for k in range(3)]
    assert sorted(k for k, v in _snapshot(base).items() if v is not None) == sorted(names)
    assert written["rgb"] == str(base / "rgb" / "000002.png") and len(written["mask_visib"]) == 3

    scene_camera = load_json(base / "scene_camera.json", keys_to_int=True)
    scene_gt = load_json(base / "scene_gt.json", keys_to_int=True)
    scene_gt_info = load_json(base / "scene_gt_info.json", keys_to_int=True)
    assert list(scene_camera) == list(scene_gt) == list(scene_gt_info) == [2]
    assert '"2": ' in (base / "scene_gt.json").read_text()  # keys are the im_id as a string
    cam = scene_camera[2]
    K = np.array(cam["cam_K"]).reshape(3, 3)
    np.testing.assert_array_equal(K, [[58.0, 0.0, 30.7], [0.0, 60.0, 24.2], [0.0, 0.0, 1.0]])
    R_w2c, t_w2c = np.array(cam["cam_R_w2c"]).reshape(3, 3), np.array(cam["cam_t_w2c"])
    depth_scale = cam["depth_scale"]
    assert depth_scale == 0.1

    # depth: PNG value x depth_scale is the depth in mm, to half a step
    depth_mm = load_depth(written["depth"]) * depth_scale
    assert png_bit_depth(written["depth"]) == (16, 0)  # 16-bit greyscale
    assert np.abs(depth_mm - frame.depth.astype(np.float64) * 1000.0).max() <= depth_scale / 2 + 1e-3
    assert np.array_equal(depth_mm > 0, frame.instance > 0)
    # rgb: the frame's 8-bit sRGB
    np.testing.assert_array_equal(imread(written["rgb"]), frame.to_srgb8())

    # the camera: a world point's camera-frame z is the depth the render shows at the pixel it projects to
    gts, infos = scene_gt[2], scene_gt_info[2]
    assert [g["obj_id"] for g in gts] == [1, 2, 1]
    for obj, gt in zip(scene.objects, gts):
        R_m2c, t_m2c = np.array(gt["cam_R_m2c"]).reshape(3, 3), np.array(gt["cam_t_m2c"])
        np.testing.assert_allclose(R_m2c.T @ R_m2c, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(R_m2c, R_w2c @ obj.pose[:3, :3], atol=1e-12)
        np.testing.assert_allclose(t_m2c, R_w2c @ (1000.0 * obj.pose[:3, 3]) + t_w2c, atol=1e-9)

    masks = [load_mask(p) for p in written["mask"]]
    visib = [load_mask(p) for p in written["mask_visib"]]
    sphere_gt, box_gt, small_gt = gts
    # the sphere's whole silhouette (amodal: the box hides part of it) is centred on its centre's projection
    centre = project_pts(np.zeros((1, 3)), K, np.array(sphere_gt["cam_R_m2c"]).reshape(3, 3),
                         np.array(sphere_gt["cam_t_m2c"]))[0]
    ys, xs = np.nonzero(masks[0])
    assert np.hypot(xs.mean() - centre[0], ys.mean() - centre[1]) < 1.0, (xs.mean(), ys.mean(), centre)
    # its nearest point, 500 mm in front of its centre along the ray, is the depth at that pixel
    u, v = np.round(centre).astype(int)
    t = np.array(sphere_gt["cam_t_m2c"])
    if visib[0][v, u]:
        assert abs(depth_mm[v, u] - (np.linalg.norm(t) - 500.0)) < 5.0
    else:  # hidden by the box: the box is nearer
        assert depth_mm[v, u] < np.linalg.norm(t) - 500.0
    # the box's corners, projected, span its whole silhouette's box (to a pixel: corners land inside pixels)
    corners = 1000.0 * HALF * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    uv = project_pts(corners, K, np.array(box_gt["cam_R_m2c"]).reshape(3, 3), np.array(box_gt["cam_t_m2c"]))
    x0, y0, w, h = infos[1]["bbox_obj"]
    np.testing.assert_allclose([x0, y0, x0 + w, y0 + h], [*uv.min(axis=0), *uv.max(axis=0)], atol=1.0)

    for k, obj in enumerate(scene.objects):
        info = infos[k]
        # mask_visib is the instance pass; mask the object rendered alone; the visible part lies inside the whole
        assert np.array_equal(visib[k], frame.instance == obj.instance_id)
        alone = glphong.Scene(scene.camera, scene.lights)
        alone.add(obj.mesh, obj.material, pose=obj.pose, instance_id=obj.instance_id)
        assert np.array_equal(masks[k], renderer.render(alone, passes=("instance",)).instance > 0)
        assert not np.any(visib[k] & ~masks[k])
        assert info["px_count_visib"] == visib[k].sum() > 0
        assert info["px_count_valid"] == np.count_nonzero(depth_mm[masks[k]] > 0) == masks[k].sum()
        assert info["visib_fract"] == pytest.approx(info["px_count_visib"] / info["px_count_all"], rel=1e-12)
        assert info["bbox_visib"] == calc_2d_bbox(*np.nonzero(visib[k])[::-1])
    # the box hides part of the sphere; nothing hides the box
    assert masks[0].sum() > visib[0].sum() and infos[0]["visib_fract"] < 0.95
    assert infos[0]["px_count_all"] == masks[0].sum()
    assert infos[0]["bbox_obj"] == calc_2d_bbox(*np.nonzero(masks[0])[::-1])
    assert infos[1]["visib_fract"] == 1.0 and np.array_equal(masks[1], visib[1])
    # the small sphere is cut off by the right edge: its whole silhouette counts beyond the image (calc_gt_info.py)
    assert infos[2]["px_count_all"] > masks[2].sum()
    x0, y0, w, h = infos[2]["bbox_obj"]
    assert x0 + w > W - 1 and infos[2]["visib_fract"] < 1.0
    # its radius in pixels from the whole count: pi r^2 ~ px_count_all, r ~ f 300 / z
    z = small_gt["cam_t_m2c"][2]
    assert infos[2]["px_count_all"] == pytest.approx(np.pi * (59.0 * 300.0 / z) ** 2, rel=0.1)
    # without count_truncated: the image's pixels only
    write_bop(tmp_path / "inside", scene, renderer, obj_ids=OBJ_IDS, count_truncated=False)
    info = load_json(tmp_path / "inside" / "000000" / "scene_gt_info.json", keys_to_int=True)[0][2]
    assert info["px_count_all"] == masks[2].sum() and info["bbox_obj"] == calc_2d_bbox(*np.nonzero(masks[2])[::-1])


@pytest.mark.parametrize("kind", ["perspective", "intrinsics at twice the size"])
def test_cam_k_projects_as_glphong_does(kind):
    """cam_K sends each pixel centre's ray (glphong's own, `Camera.pixel_rays`) to that pixel's integer position."""
    pose = glphong.PerspectiveCamera.look_at((0.4, -0.2, 2.0), (0.1, 0.0, 0.0)).pose
    if kind == "perspective":
        camera, width, height = glphong.PerspectiveCamera(0.9, pose=pose), 40, 30
    else:
        camera, width, height = glphong.IntrinsicsCamera(50.0, 52.0, 19.3, 14.8, 40, 30, pose=pose), 80, 60
    K = bop_camera_matrix(camera, width, height)
    R, _ = bop_world_to_camera(camera)
    _, directions = camera.pixel_rays(width, height)
    d = directions @ R.T
    uv = (d @ K.T)[..., :2] / d[..., 2:]
    v, u = np.mgrid[0:height, 0:width]
    np.testing.assert_allclose(uv[..., 0], u, atol=1e-9)
    np.testing.assert_allclose(uv[..., 1], v, atol=1e-9)


def test_perspective_camera_lands_where_rendered(glphong_backend, glphong_make_renderer, tmp_path):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.2, 3.2), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(SMALL, glphong.Lambert(0.5), pose=_pose((0.5, 0.3, 0.1), 0.3), instance_id=2)
    # a small sphere wholly behind it, on the ray from the camera through its centre
    scene.add(primitives.sphere(2, 0.05), glphong.Lambert(0.5), pose=_pose((0.6, 0.32, -0.52)), instance_id=9)
    written = write_bop(tmp_path, scene, glphong_make_renderer(W, H, glphong_backend))
    hidden = load_json(written["scene_gt_info"], keys_to_int=True)[0][1]
    assert hidden["px_count_all"] == load_mask(written["mask"][1]).sum() > 0
    assert hidden["px_count_visib"] == 0 == load_mask(written["mask_visib"][1]).sum()
    # nothing visible: both boxes are [-1, -1, -1, -1] (calc_gt_info.py), visib_fract 0
    assert hidden["bbox_obj"] == hidden["bbox_visib"] == [-1, -1, -1, -1] and hidden["visib_fract"] == 0.0
    cam = load_json(written["scene_camera"], keys_to_int=True)[0]
    gt = load_json(written["scene_gt"], keys_to_int=True)[0][0]
    assert gt["obj_id"] == 2  # the default: the instance id
    centre = project_pts(np.zeros((1, 3)), np.array(cam["cam_K"]).reshape(3, 3),
                         np.array(gt["cam_R_m2c"]).reshape(3, 3), np.array(gt["cam_t_m2c"]))[0]
    ys, xs = np.nonzero(load_mask(written["mask"][0]))
    assert np.hypot(xs.mean() - centre[0], ys.mean() - centre[1]) < 1.0


def test_images_accumulate_and_rewriting_is_idempotent(glphong_backend, glphong_make_renderer, tmp_path):
    renderer = glphong_make_renderer(W, H, glphong_backend)
    write_bop(tmp_path, _scene(), renderer, im_id=0, obj_ids=OBJ_IDS)
    first = _snapshot(tmp_path)
    write_bop(tmp_path, _scene(shift=0.2), renderer, im_id=1, obj_ids=OBJ_IDS, depth_scale=0.5)
    base = tmp_path / "000000"
    for name in ("scene_camera", "scene_gt", "scene_gt_info"):
        assert sorted(load_json(base / f"{name}.json", keys_to_int=True)) == [0, 1], name
    for name in ("scene_camera", "scene_gt", "scene_gt_info"):  # laid out as the toolkit's save_json lays it out
        text = (base / f"{name}.json").read_text()
        assert text == save_json_text(load_json(base / f"{name}.json", keys_to_int=True)), name
    cameras = load_json(base / "scene_camera.json", keys_to_int=True)
    assert cameras[0]["depth_scale"] == 0.1 and cameras[1]["depth_scale"] == 0.5
    gt = load_json(base / "scene_gt.json", keys_to_int=True)
    assert gt[1][0]["cam_t_m2c"] != gt[0][0]["cam_t_m2c"]
    # image 0's own files are untouched by image 1
    after = _snapshot(tmp_path)
    assert all(after[k] == v for k, v in first.items() if "000000_" in k or k.endswith("000000.png"))
    # the same image again: the same bytes everywhere (another depth_scale is allowed: the depth is rewritten)
    write_bop(tmp_path, _scene(), renderer, im_id=0, obj_ids=OBJ_IDS, depth_scale=0.2)
    assert load_json(base / "scene_camera.json", keys_to_int=True)[0]["depth_scale"] == 0.2
    write_bop(tmp_path, _scene(), renderer, im_id=0, obj_ids=OBJ_IDS)
    assert _snapshot(tmp_path) == after
    # image 0 again with fewer objects: its masks of objects no longer there are gone
    write_bop(tmp_path, _scene(objects=1), renderer, im_id=0, obj_ids=OBJ_IDS)
    names = set(_snapshot(base))
    assert "mask/000000_000000.png" in names and "mask/000000_000001.png" not in names
    assert "mask_visib/000000_000002.png" not in names and "mask/000001_000002.png" in names
    assert len(load_json(base / "scene_gt_info.json", keys_to_int=True)[0]) == 1
    assert not [n for n in names if n.endswith(".tmp")]
    # an image with no object: empty lists
    empty = glphong.Scene(_camera(), [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    written = write_bop(tmp_path, empty, renderer, im_id=12)
    assert written["mask"] == [] and load_json(written["scene_gt"], keys_to_int=True)[12] == []
    assert load_json(written["scene_gt_info"], keys_to_int=True)[12] == []
    assert not load_depth(written["depth"]).any()


def _moved_camera():
    return _scene(camera=_camera(eye=(0.25, 0.3, 3.0)))


def _scaled():
    scene = _scene(objects=1)
    scene.add(BOX, glphong.Lambert(0.5), pose=np.diag([1.1, 1.0, 1.0, 1.0]), instance_id=5)
    return scene


def _sheared():
    pose = np.eye(4)
    pose[0, 1] = 0.05
    scene = _scene(objects=1)
    scene.add(BOX, glphong.Lambert(0.5), pose=pose, instance_id=5)
    return scene


def _mirrored():
    scene = _scene(objects=1)
    scene.add(BOX, glphong.Lambert(0.5), pose=np.diag([-1.0, 1.0, 1.0, 1.0]), instance_id=5)
    return scene


def _orthographic():
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    scene.add(SPHERE, glphong.Lambert(0.5))
    return scene


def _corrupt(text):
    def corrupt(folder):
        (folder / "000000" / "scene_gt.json").write_text(text)
    return corrupt


def _camera_list(folder):
    (folder / "000000" / "scene_camera.json").write_text("[1, 2]")


def _folder_is_file(folder):
    (folder / "000007").write_text("not a folder")


# (what is wrong, write_bop's arguments beyond folder/renderer, a change made to the folder first, error, message)
BAD = [
    ("scaled pose", dict(scene=_scaled, obj_ids=None), None, ValueError, "must be rigid"),
    ("sheared pose", dict(scene=_sheared, obj_ids=None), None, ValueError, "R\\^T R - I"),
    ("mirrored pose", dict(scene=_mirrored, obj_ids=None), None, ValueError, "determinant"),
    ("obj_ids misses one", dict(obj_ids={3: 1, 5: 2}), None, ValueError, "instance_id 8"),
    ("obj_ids of 0", dict(obj_ids={3: 1, 5: 0, 8: 1}), None, ValueError, r"obj_ids\[5\]"),
    ("obj_ids negative", dict(obj_ids={3: -1, 5: 2, 8: 1}), None, ValueError, r"obj_ids\[3\]"),
    ("obj_ids float", dict(obj_ids={3: 1.0, 5: 2, 8: 1}), None, ValueError, r"obj_ids\[3\]"),
    ("obj_ids bool", dict(obj_ids={3: True, 5: 2, 8: 1}), None, ValueError, r"obj_ids\[3\]"),
    ("obj_ids a list", dict(obj_ids=[1, 2, 1]), None, TypeError, "mapping"),
    ("scene_id negative", dict(scene_id=-1), None, ValueError, "scene_id"),
    ("scene_id too big", dict(scene_id=1000000), None, ValueError, "scene_id"),
    ("scene_id float", dict(scene_id=1.0), None, TypeError, "scene_id"),
    ("scene_id str", dict(scene_id="1"), None, TypeError, "scene_id"),
    ("im_id negative", dict(im_id=-3), None, ValueError, "im_id"),
    ("im_id too big", dict(im_id=10 ** 6), None, ValueError, "im_id"),
    ("im_id bool", dict(im_id=True), None, TypeError, "im_id"),
    ("orthographic", dict(scene=_orthographic, obj_ids=None), None, ValueError, "OrthographicCamera"),
    ("depth beyond 16 bits", dict(depth_scale=0.01, im_id=1), None, ValueError, "depth_scale >="),
    ("depth_scale 0", dict(depth_scale=0.0), None, ValueError, "depth_scale"),
    ("another camera", dict(scene=_moved_camera), None, SceneFileError, "another camera"),
    ("scene_gt.json not JSON", {}, _corrupt("{ nope"), SceneFileError, "scene_gt.json"),
    ("scene_gt.json nested too deeply", {}, _corrupt("[" * 200000), SceneFileError, "nested too deeply"),
    ("scene_gt.json a list", {}, _corrupt("[]"), SceneFileError, "scene_gt.json"),
    ("scene_gt.json bad key", {}, _corrupt('{"x": []}'), SceneFileError, "scene_gt.json"),
    ("scene_gt.json bad entry", {}, _corrupt('{"0": 5}'), SceneFileError, "scene_gt.json"),
    ("scene_camera.json a list", {}, _camera_list, SceneFileError, "scene_camera.json"),
    ("scene folder a file", dict(scene_id=7), _folder_is_file, ValueError, "must be a folder"),
    ("scene not a Scene", dict(scene=lambda: "scene"), None, TypeError, "scene must be"),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_bad_input_raises_and_writes_nothing(glphong_make_renderer, tmp_path, case):
    _, arguments, change, error, message = case
    renderer = glphong_make_renderer(W, H, "osmesa")
    write_bop(tmp_path, _scene(), renderer, im_id=0, obj_ids=OBJ_IDS)  # a folder with one image already
    if change is not None:
        change(tmp_path)
    before = _snapshot(tmp_path)
    arguments = dict(arguments)
    scene = arguments.pop("scene", _scene)()
    arguments.setdefault("obj_ids", OBJ_IDS)
    with pytest.raises(error, match=message):
        write_bop(tmp_path, scene, renderer, **arguments)
    assert _snapshot(tmp_path) == before


def test_the_renderer_keeps_its_size(glphong_make_renderer, tmp_path):
    renderer = glphong_make_renderer(W, H, "osmesa")
    write_bop(tmp_path, _scene(), renderer, obj_ids=OBJ_IDS)
    assert (renderer.width, renderer.height) == (W, H)
    with pytest.raises(TypeError, match="renderer must be"):
        write_bop(tmp_path, _scene(), "renderer")
    with pytest.raises(TypeError, match="folder must be"):
        write_bop(3, _scene(), renderer)
