"""BOP scenes written by batches (`render_many(..., fmt='bop')`, `glphong.batch.bop_images`) and the whole
silhouettes behind their masks made from fewer renders (`glphong.datasets.bop_masks`).

- the silhouettes equal one render per object and canvas (the way `write_bop` made them before, restated here as
  `reference_silhouettes`), pixel for pixel, for objects inside the image, across each border, wholly outside,
  through the near plane, hidden behind each other, apart and crowded, drawn by another program in a group (a
  textured neighbour), on both backends; and `write_bop`'s files are the same bytes with either;
- a batch writes the files `write_bop` writes image by image, byte for byte, on both backends (in this process),
  and with a two-worker 'spawn' pool over two interleaved scene ids, which never mix;
- a batch interrupted mid-way (its JSON files then hold the images done, and only those), resumed, ends with the
  files of an uninterrupted batch; corrupted, unrecorded and half-written files are made again;
- bad arguments fail with the argument named, before anything is written; a scene that cannot be written as BOP
  fails with write_bop's message; a BOP folder without a manifest is not adopted.

Images are 64x48 (the pool's: 48x40); the batches that need no worker process run their tasks in this process
(`InlineExecutor`), the folder's bookkeeping being the same for every executor.
"""
import hashlib
import json
import os
import sys

import numpy as np
import pytest

import glphong
import glphong.datasets.bop as bop_module
from glphong import primitives
from glphong.testing import InlineExecutor
from glphong.batch import BatchError, render_many, tabletop_scene
from glphong.datasets import write_bop
from glphong.datasets.bop import bop_camera_matrix
from glphong.datasets.bop_masks import silhouettes
from glphong.scene.camera import IntrinsicsCamera

W, H = 64, 48
LIGHTS = [glphong.PointLight((2.0, 2.0, 3.0), 50.0)]


def snapshot(folder, skip=("manifest.json", "frames.jsonl", ".lock")):
    """Every file under ``folder`` (but the batch's own) with its bytes' SHA-256, by relative path."""
    out = {}
    for root, _, files in os.walk(folder):
        for name in files:
            path = os.path.join(root, name)
            if os.path.relpath(path, folder) not in skip:
                with open(path, "rb") as handle:
                    out[os.path.relpath(path, folder)] = hashlib.sha256(handle.read()).hexdigest()
    return out


def write_each(folder, ids, renderer, specs=None, **keywords):
    """The reference: `write_bop` called image by image for ``tabletop_scene(spec)``, spec ``i`` as ``ids[i]``."""
    for spec, (scene_id, im_id) in zip(range(len(ids)) if specs is None else specs, ids):
        write_bop(folder, tabletop_scene(spec), renderer, scene_id=scene_id, im_id=im_id, **keywords)
    return snapshot(folder)


# -- the silhouettes --------------------------------------------------------------------------------------------------

def reference_silhouettes(scene, renderer, count_truncated):
    """One render per object alone at the image's size, and one per object on the canvas three times its size:
    what `write_bop` did before `glphong.datasets.bop_masks` (and bop_toolkit's calc_gt_info.py does)."""
    width, height = renderer.width, renderer.height

    def alone(obj, camera):
        single = glphong.Scene(camera, scene.lights, scene.ambient)
        single.add(obj.mesh, obj.material, pose=obj.pose, instance_id=obj.instance_id, category=obj.category)
        return renderer.render(single, passes=("instance",)).instance != 0

    inside = [alone(obj, scene.camera) for obj in scene.objects]
    if not count_truncated:
        return [(m, (np.zeros(0, np.int64),) * 2) for m in inside]
    k = bop_camera_matrix(scene.camera, width, height)
    large = IntrinsicsCamera(k[0, 0], k[1, 1], k[0, 2] + width, k[1, 2] + height, 3 * width, 3 * height,
                             pose=scene.camera.pose, znear=scene.camera.znear, zfar=scene.camera.zfar)
    out = []
    renderer.resize(3 * width, 3 * height)
    try:
        for obj, mask in zip(scene.objects, inside):
            big = alone(obj, large)
            big[height:2 * height, width:2 * width] = False
            ys, xs = np.nonzero(big)
            out.append((mask, (ys - height, xs - width)))
    finally:
        renderer.resize(width, height)
    return out


def _pose(x, y, z, turn=0.0):
    pose = np.eye(4)
    c, s = np.cos(turn), np.sin(turn)
    pose[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    pose[:3, 3] = (x, y, z)
    return pose


SPHERE = primitives.sphere(3, 0.25)
TEXTURE = glphong.Texture(np.random.default_rng(3).random((4, 4, 3)).astype(np.float32))


def _case(placed, znear=0.05):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.7, znear=znear)
    scene = glphong.Scene(camera, LIGHTS)
    for i, (x, y, z, *material) in enumerate(placed):
        scene.add(SPHERE, material[0] if material else glphong.Lambert(0.5), pose=_pose(x, y, z, 0.3 * i),
                  instance_id=10 + i)
    return scene


#: (name, objects (x, y, z[, material]), znear, how many renders at most: image size, large canvas)
CASES = [
    ("apart, inside", [(-0.7, 0.0, 0.0), (0.7, 0.1, 0.0), (0.0, -0.6, -0.5)], 0.05, (1, 0)),
    ("one hides another", [(0.0, 0.0, 0.0), (0.1, 0.05, 0.8), (-0.8, 0.3, 0.0)], 0.05, (2, 0)),
    ("across each border", [(-1.25, 0.0, 0.0), (1.3, 0.1, 0.0), (0.0, 0.95, 0.0), (0.2, -0.95, 0.0),
                            (0.0, 0.0, 0.0)], 0.05, (1, 1)),
    ("wholly outside the image", [(2.5, 0.0, 0.0), (0.0, 0.0, 0.0)], 0.05, (1, 1)),
    ("through the near plane", [(0.0, 0.0, 2.7), (0.5, 0.2, 0.0)], 0.4, (2, 1)),
    ("a textured neighbour", [(-0.6, 0.0, 0.0), (0.6, 0.0, 0.0, glphong.Lambert(kd=TEXTURE))], 0.05, (2, 0)),
    ("a textured alpha mask", [(-0.1, 0.0, 0.0), (0.2, 0.1, 0.3, glphong.Lambert(0.5, alpha_mask=glphong.AlphaMask(
        0.5, glphong.Texture(np.array([[255, 0], [0, 255]], np.uint8), 1.0, srgb=False, channel="r"))))],
     0.05, (2, 0)),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_silhouettes_equal_one_render_per_object(glphong_backend, glphong_make_renderer, case):
    _, placed, znear, (most_small, most_large) = case
    scene = _case(placed, znear)
    renderer = glphong_make_renderer(W, H, glphong_backend)
    expected = reference_silhouettes(scene, renderer, True)
    calls = []
    render = renderer.render
    renderer.render = lambda *a, **k: calls.append(renderer.width) or render(*a, **k)
    try:
        got = silhouettes(scene, renderer, bop_camera_matrix(scene.camera, W, H), True)
    finally:
        renderer.render = render
    assert (renderer.width, renderer.height) == (W, H)
    for (inside, outside), (want_inside, want_outside) in zip(got, expected):
        assert np.array_equal(inside, want_inside)
        assert np.array_equal(outside[0], want_outside[0]) and np.array_equal(outside[1], want_outside[1])
    assert calls.count(W) <= most_small and calls.count(3 * W) <= most_large, calls
    assert any(o[0].size for _, o in expected) == (most_large > 0)  # the cases that need the canvas have a cut part


#: the objects drawn alone at the image's size when the frame's own instance pass gives those apart from all others
FROM_THE_FRAME = {"apart, inside": 0, "one hides another": 2, "across each border": 0, "wholly outside the image": 0,
                  "through the near plane": 2, "a textured neighbour": 0, "a textured alpha mask": 0}


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_silhouettes_from_the_frame_equal_one_render_per_object(glphong_backend, glphong_make_renderer, case):
    """An object whose region meets no other's takes its silhouette from the frame's instance pass (drawn by the
    radiance program with its planes: the same invariant gl_Position); the others are drawn alone
    (`glphong.Renderer.silhouettes`): the same pixels as one render per object, no render of a scene."""
    name, placed, znear, _ = case
    scene = _case(placed, znear)
    renderer = glphong_make_renderer(W, H, glphong_backend)
    expected = reference_silhouettes(scene, renderer, True)
    frame = renderer.render(scene, passes=("radiance", "depth", "instance"))
    calls, drawn = [], []
    render, draw = renderer.render, renderer.silhouettes
    renderer.render = lambda *a, **k: calls.append(renderer.width) or render(*a, **k)
    renderer.silhouettes = lambda s, i: drawn.extend([renderer.width] * len(i)) or draw(s, i)
    try:
        got = silhouettes(scene, renderer, bop_camera_matrix(scene.camera, W, H), True, visible=frame.instance)
    finally:
        renderer.render, renderer.silhouettes = render, draw
    for (inside, outside), (want_inside, want_outside) in zip(got, expected):
        assert np.array_equal(inside, want_inside)
        assert np.array_equal(outside[0], want_outside[0]) and np.array_equal(outside[1], want_outside[1])
    if "alpha" in name:  # a draw of its own does not follow a textured alpha mask: each object rendered alone
        assert drawn == [] and calls == [W, W], calls
    else:
        assert calls == [] and drawn.count(W) == FROM_THE_FRAME[name], drawn


def test_write_bop_files_equal_the_reference(glphong_backend, glphong_make_renderer, tmp_path, monkeypatch):
    renderer = glphong_make_renderer(W, H, glphong_backend)
    scenes = [_case(placed, znear) for _, placed, znear, _ in CASES] + [tabletop_scene(s) for s in range(3)]
    for i, scene in enumerate(scenes):
        write_bop(tmp_path / "new", scene, renderer, im_id=i)
    monkeypatch.setattr(bop_module, "silhouettes", lambda s, r, k, c, large, visible=None: reference_silhouettes(s, r, c))
    for i, scene in enumerate(scenes):
        write_bop(tmp_path / "reference", scene, renderer, im_id=i)
    assert snapshot(tmp_path / "new") == snapshot(tmp_path / "reference")


# -- batches ----------------------------------------------------------------------------------------------------------

def test_a_batch_writes_what_write_bop_writes(glphong_backend, glphong_make_renderer, tmp_path):
    """In the batch's worker the large canvas has a renderer of its own; write_bop resizes its renderer: the same
    bytes (specs 7 and 9 have an object across the border)."""
    specs = [0, 7, 2, 9, 4]
    paths = render_many(tabletop_scene, specs, W, H, tmp_path / "batch", executor=InlineExecutor(), fmt="bop",
                        frames_per_scene=3, obj_ids="category", progress=False, backend=glphong_backend)
    ids = [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1)]
    assert paths == [str(tmp_path / "batch" / f"{s:06d}" / "rgb" / f"{i:06d}.png") for s, i in ids]
    renderer = glphong_make_renderer(W, H, glphong_backend)
    expected = write_each(tmp_path / "reference", ids, renderer, specs, obj_ids="category")
    assert snapshot(tmp_path / "batch") == expected
    info = json.loads((tmp_path / "batch" / "000000" / "scene_gt_info.json").read_text())["1"]
    assert any(o["bbox_obj"][0] + o["bbox_obj"][2] >= W or o["bbox_obj"][1] + o["bbox_obj"][3] >= H
               or min(o["bbox_obj"][:2]) < 0 for o in info)  # spec 7: cut by the border
    assert sorted(os.listdir(tmp_path / "batch")) == [".lock", "000000", "000001", "frames.jsonl", "manifest.json"]
    gt = json.loads((tmp_path / "batch" / "000001" / "scene_gt.json").read_text())
    assert list(gt) == ["0", "1"] and {g["obj_id"] for g in gt["0"]} <= {1, 2, 3}
    manifest = json.loads((tmp_path / "batch" / "manifest.json").read_text())
    assert manifest["format"] == "bop" and manifest["bop"]["obj_ids"] == "category"


SCENE_MODULE = """
import os

from glphong.batch import tabletop_scene

MARKER = {marker!r}


def scene_of(spec):
    '''The tabletop scene of seed spec[0] (the spec's second item: which BOP image it becomes); the first time it
    meets seed 3 it kills its worker.'''
    if spec[0] == 3 and not os.path.exists(MARKER):
        open(MARKER, "w").close()
        os._exit(9)
    return tabletop_scene(spec[0])
"""


def test_two_workers_two_scene_ids_never_mix(tmp_path):
    """A 2-worker 'spawn' pool, one image a task, the frames of scenes 3 and 7 interleaved, a worker killed
    mid-batch: each scene's files and JSON entries are its own and equal write_bop's, no temporary file left."""
    (tmp_path / "bop_batch_scenes.py").write_text(SCENE_MODULE.format(marker=str(tmp_path / "died")))
    sys.path.insert(0, str(tmp_path))
    try:
        module = __import__("bop_batch_scenes")
        ids = [(3, 0), (7, 0), (3, 1), (7, 5), (3, 2), (7, 1)]
        specs = [(seed, pair) for seed, pair in enumerate(ids)]
        render_many(module.scene_of, specs, 48, 40, tmp_path / "batch", fmt="bop", bop_ids=ids, workers=2,
                    progress=False)
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("bop_batch_scenes", None)
    assert (tmp_path / "died").exists()
    with glphong.Renderer(48, 40) as renderer:
        assert snapshot(tmp_path / "batch") == write_each(tmp_path / "reference", ids, renderer)
    for scene_id, images in ((3, ["0", "1", "2"]), (7, ["0", "1", "5"])):
        for name in ("scene_camera", "scene_gt", "scene_gt_info"):
            text = (tmp_path / "batch" / f"{scene_id:06d}" / f"{name}.json").read_text()
            assert list(json.loads(text)) == images


def test_an_interrupted_batch_resumes_to_the_same_files(tmp_path):
    specs = list(range(6))
    keywords = dict(fmt="bop", frames_per_scene=4, progress=False)
    whole = tmp_path / "whole"
    render_many(tabletop_scene, specs, W, H, whole, executor=InlineExecutor(), **keywords)
    expected = snapshot(whole)

    out = tmp_path / "batch"
    with pytest.raises(KeyboardInterrupt):
        render_many(_stopped_at_3, specs, W, H, out, executor=InlineExecutor(), **keywords)
    # the JSON files written on the way out hold the images done and no other (here the tasks ran as they were
    # submitted: images 4 and 5 came back before the interruption was seen, and were journalled), and every file is whole
    partial = snapshot(out)
    for scene_id, images in ((0, ["0", "1", "2"]), (1, ["0", "1"])):
        for name in ("scene_camera", "scene_gt", "scene_gt_info"):
            assert list(json.loads((out / f"{scene_id:06d}" / f"{name}.json").read_text())) == images
    assert all(expected[name] == digest for name, digest in partial.items() if not name.endswith(".json"))
    # a writer killed mid-write left a temporary file; image 1's mask was damaged; image 2's record was lost
    (out / "000000" / "rgb" / ".000003.png.0123456789abcdef.tmp").write_bytes(b"half")
    with open(out / "000000" / "mask" / "000001_000000.png", "r+b") as handle:
        handle.truncate(20)
    journal = (out / "frames.jsonl").read_text().splitlines(keepends=True)
    (out / "frames.jsonl").write_text("".join(line for line in journal if json.loads(line)["index"] != 2))
    stamp = os.stat(out / "000000" / "rgb" / "000000.png").st_mtime_ns
    render_many(tabletop_scene, specs, W, H, out, executor=InlineExecutor(), **keywords)
    assert snapshot(out) == expected
    assert os.stat(out / "000000" / "rgb" / "000000.png").st_mtime_ns == stamp  # a trusted image is kept
    # a rerun of the finished batch renders nothing and changes nothing
    stamps = {name: os.stat(out / name).st_mtime_ns for name in expected}
    render_many(tabletop_scene, specs, W, H, out, executor=InlineExecutor(lambda n: pytest.fail("rendered")),
                **keywords)
    assert {name: os.stat(out / name).st_mtime_ns for name in expected} == stamps


def _stopped_at_3(spec):
    """The tabletop scene; the user stops the batch (Ctrl-C) at spec 3."""
    if spec == 3:
        raise KeyboardInterrupt
    return tabletop_scene(spec)


def _bent(spec):
    scene = tabletop_scene(spec)
    obj = scene.objects[0]
    scene.add(obj.mesh, obj.material, pose=np.diag([1.1, 1.0, 1.0, 1.0]), instance_id=9, category=1)
    return scene


# (what is wrong, render_many's keywords, error, message)
BAD = [
    ("BOP arguments with fmt='png'", dict(fmt="png", frames_per_scene=2), ValueError, "frames_per_scene belong"),
    ("bop_ids and frames_per_scene", dict(bop_ids=[(0, 0), (0, 1)], frames_per_scene=2), ValueError, "not both"),
    ("bop_ids not one per spec", dict(bop_ids=[(0, 0)]), ValueError, "2 specs, 1 pairs"),
    ("bop_ids twice the same", dict(bop_ids=[(4, 2), (4, 2)]), ValueError, r"bop_ids\[0\] and bop_ids\[1\]"),
    ("bop_ids not pairs", dict(bop_ids=[0, 1]), TypeError, r"bop_ids\[0\] must be a \(scene_id, im_id\)"),
    ("im_id too big", dict(bop_ids=[(0, 0), (0, 10 ** 6)]), ValueError, r"bop_ids\[1\]'s im_id"),
    ("scene_id negative", dict(bop_ids=[(-1, 0), (0, 0)]), ValueError, r"bop_ids\[0\]'s scene_id"),
    ("frames_per_scene 0", dict(frames_per_scene=0), ValueError, "frames_per_scene"),
    ("obj_ids a list", dict(obj_ids=[1, 2]), TypeError, "obj_ids must be a mapping"),
    ("obj_ids another word", dict(obj_ids="instance"), ValueError, "or 'category'"),
    ("obj_ids of 0", dict(obj_ids={1: 0}), ValueError, r"obj_ids\[1\]"),
    ("depth_scale 0", dict(depth_scale=0.0), ValueError, "depth_scale"),
    ("count_truncated a word", dict(count_truncated="yes"), TypeError, "count_truncated"),
    ("passes", dict(passes=("depth",)), ValueError, "fmt='bop' writes what BOP holds"),
    ("a canvas beyond the limit", dict(count_truncated=True, supersample=8), ValueError, "count_truncated=False"),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_bad_arguments_fail_before_anything_is_written(tmp_path, case):
    _, keywords, error, message = case
    keywords = {"fmt": "bop", **keywords}
    size = 800 if "supersample" in keywords else W
    with pytest.raises(error, match=message):
        render_many(tabletop_scene, [0, 1], size, size, tmp_path / "batch", executor=InlineExecutor(),
                    progress=False, **keywords)
    assert not (tmp_path / "batch").exists()


def test_scenes_and_folders_bop_cannot_take(glphong_make_renderer, tmp_path):
    inline = dict(executor=InlineExecutor(), fmt="bop", progress=False)
    # a pose that is not rigid: write_bop's message, from the worker (the frame named), and nothing written
    with pytest.raises(BatchError, match="must be rigid"):
        render_many(_bent, [0], W, H, tmp_path / "bent", **inline)
    assert sorted(os.listdir(tmp_path / "bent")) == [".lock", "frames.jsonl", "manifest.json"]
    # obj_ids that miss an object of a frame
    with pytest.raises(BatchError, match="instance_id 2"):
        render_many(tabletop_scene, [0], W, H, tmp_path / "missing", obj_ids={1: 1}, **inline)
    # a BOP folder written image by image (no manifest) is not adopted
    write_bop(tmp_path / "split", tabletop_scene(0), glphong_make_renderer(W, H, "osmesa"))
    before = snapshot(tmp_path / "split")
    with pytest.raises(BatchError, match="holds 000000 but no manifest.json"):
        render_many(tabletop_scene, [0], W, H, tmp_path / "split", **inline)
    assert snapshot(tmp_path / "split", skip=(".lock",)) == before
    # a file where a scene's folder goes
    (tmp_path / "taken").mkdir()
    (tmp_path / "taken" / "000000").write_text("not a folder")
    with pytest.raises(BatchError, match="must be a folder of BOP scene 0"):
        render_many(tabletop_scene, [0], W, H, tmp_path / "taken", **inline)
