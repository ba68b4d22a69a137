"""`glphong.datasets.coco`: instance masks of real renders written as COCO JSON and read back by pycocotools itself.

A sphere partly hides a box behind it (64x48, an OpenCV camera); each annotation's mask, read with
``pycocotools.coco.COCO(path).annToMask``, must equal ``frame.instance == id`` exactly, its area the pixel count and
its box the mask's box computed with numpy; errors are clear and leave no file.
"""
import json
import sys

import numpy as np
import pytest
import trimesh
from pycocotools import mask as mask_api
from pycocotools.coco import COCO

import glphong
from glphong import primitives
from glphong.datasets.coco import CocoWriter, coco_annotations
from glphong.scene.geometry import MeshData

W, H = 64, 48
SPHERE = primitives.sphere(3, 0.5)
BOX = MeshData.from_trimesh(trimesh.creation.box((0.8, 0.6, 0.6)), smooth=False)
SPHERE_ID, BOX_ID = 7, 2
CATEGORIES = {3: "ball", 5: "box", 9: "unused"}
# pycocotools' own decode, under NumPy 2 (not glphong's code)
pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation doesn't accept a copy:DeprecationWarning")


def _translate(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def _scene(shift=0.0, sphere=True, box=True, box_category=5):
    pose = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0)).pose
    camera = glphong.IntrinsicsCamera(60.0, 58.0, 31.5, 23.5, W, H, pose=pose)
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    if sphere:
        scene.add(SPHERE, glphong.Phong(0.2, 0.4, 20.0), pose=_translate(0.15 + shift, 0.05, 0.5),
                  instance_id=SPHERE_ID, category=3)
    if box:
        scene.add(BOX, glphong.Lambert(0.5), pose=_translate(-0.45, 0.0, -0.3), instance_id=BOX_ID,
                  category=box_category)
    return scene


@pytest.fixture
def render(glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(W, H, glphong_backend)

    def make(scene, passes=("radiance", "instance", "category")):
        return renderer.render(scene, passes=passes)

    return make


def _box(mask):
    """``[x, y, w, h]`` of a mask's covered pixels, by hand."""
    rows, cols = np.nonzero(mask)
    return [cols.min(), rows.min(), cols.max() - cols.min() + 1, rows.max() - rows.min() + 1]


def test_written_file_reads_back_in_pycocotools(tmp_path, render):
    frames = {"a.png": render(_scene(0.0)), "b.png": render(_scene(0.4))}
    path = tmp_path / "annotations.json"
    with CocoWriter(path, CATEGORIES) as coco:
        ids = {name: coco.add(frame, name) for name, frame in frames.items()}
        assert not path.exists()  # written when the block ends
    assert ids == {"a.png": 1, "b.png": 2}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["annotations.json"]  # no temporary file left
    dataset = COCO(str(path))
    assert sorted(dataset.getCatIds()) == [3, 5, 9] and dataset.loadCats(5)[0]["name"] == "box"
    annotation_ids = []
    for name, frame in frames.items():
        image_id = ids[name]
        image = dataset.loadImgs(image_id)[0]
        assert (image["file_name"], image["width"], image["height"]) == (name, W, H)
        annotations = dataset.loadAnns(dataset.getAnnIds(imgIds=image_id))
        seen = sorted(int(i) for i in np.unique(frame.instance) if i != 0)
        assert seen == [BOX_ID, SPHERE_ID]
        assert [a["instance_id"] for a in annotations] == seen  # one per object seen, in increasing instance id
        for annotation in annotations:
            expected = frame.instance == annotation["instance_id"]
            assert np.array_equal(dataset.annToMask(annotation).astype(bool), expected)
            assert annotation["area"] == expected.sum() > 0
            assert annotation["bbox"] == _box(expected)
            assert annotation["category_id"] == {SPHERE_ID: 3, BOX_ID: 5}[annotation["instance_id"]]
            assert annotation["iscrowd"] == 0 and annotation["image_id"] == image_id
            assert isinstance(annotation["segmentation"]["counts"], str)
            assert annotation["segmentation"]["size"] == [H, W]
            annotation_ids.append(annotation["id"])
    assert annotation_ids == [1, 2, 3, 4]  # unique across the frames


def test_an_occluded_object_gives_its_visible_pixels_only(render):
    both, alone = render(_scene()), render(_scene(sphere=False))
    whole = alone.instance == BOX_ID
    visible = both.instance == BOX_ID
    assert visible.sum() < whole.sum() and not (visible & ~whole).any()  # the sphere hides part of the box
    result = coco_annotations(both, 12, "frame.png")
    box = next(a for a in result["annotations"] if a["instance_id"] == BOX_ID)
    segmentation = {"size": box["segmentation"]["size"], "counts": box["segmentation"]["counts"].encode()}
    assert np.array_equal(mask_api.decode(segmentation).astype(bool), visible)
    assert box["area"] == visible.sum()


def test_standalone_annotations_are_json_and_numbered_from_the_first_id(render):
    frame = render(_scene())
    result = coco_annotations(frame, 0, "images/000000.png", first_annotation_id=10)
    assert result["images"] == [{"id": 0, "file_name": "images/000000.png", "width": W, "height": H}]
    assert [(a["id"], a["instance_id"]) for a in result["annotations"]] == [(10, BOX_ID), (11, SPHERE_ID)]
    assert json.loads(json.dumps(result, allow_nan=False)) == result  # plain JSON types


def test_category_zero_is_an_error_or_skipped(render):
    frame = render(_scene(box_category=0))
    with pytest.raises(ValueError, match=r"instance 2 is seen with category 0.*Scene\.add\(\.\.\., category=\)"):
        coco_annotations(frame, 1, "a.png")
    result = coco_annotations(frame, 1, "a.png", unlabelled="skip")
    assert [a["instance_id"] for a in result["annotations"]] == [SPHERE_ID]


def test_errors_are_clear_and_leave_no_file(tmp_path, render):
    frame = render(_scene())
    path = tmp_path / "coco.json"
    with pytest.raises(ValueError, match=r"the 'category' pass"):  # the pass missing
        with CocoWriter(path, CATEGORIES) as coco:
            coco.add(render(_scene(), passes=("radiance", "instance")), "a.png")
    with pytest.raises(ValueError, match=r"category ids \[5\] are not in the writer's categories \[3\]"):
        with CocoWriter(path, {3: "ball"}) as coco:
            coco.add(frame, "a.png")
    with pytest.raises(ValueError, match=r"image id 4 is already in coco\.json"):
        with CocoWriter(path, CATEGORIES) as coco:
            coco.add(frame, "a.png", image_id=4)
            coco.add(frame, "b.png", image_id=4)
    assert list(tmp_path.iterdir()) == []
    path.write_text("earlier")  # a file from before stays as it was
    with pytest.raises(ValueError, match=r"a\.png: this file name is already in coco\.json"):
        with CocoWriter(path, CATEGORIES) as coco:
            coco.add(frame, "a.png")
            coco.add(frame, "a.png")
    assert path.read_text() == "earlier" and [p.name for p in tmp_path.iterdir()] == ["coco.json"]
    # the writer is left as it was by a refused frame
    coco = CocoWriter(path, CATEGORIES)
    coco.add(frame, "a.png")
    with pytest.raises(ValueError, match="image id 1"):
        coco.add(frame, "b.png", image_id=1)
    assert len(coco.images) == 1 and len(coco.annotations) == 2
    coco.write()
    assert len(COCO(str(path)).getAnnIds()) == 2


@pytest.mark.parametrize("categories, message", [
    ({0: "background"}, r"a category id must be an integer >= 1 \(got 0\)"),
    ([{"id": 1, "name": "a"}, {"id": 1, "name": "b"}], "category id 1 is listed twice"),
    ([{"id": 1}], r"categories\[0\] must be a dict with 'id' and 'name'"),
    ({}, "categories is empty"),
])
def test_categories_are_checked(tmp_path, categories, message):
    with pytest.raises(ValueError, match=message):
        CocoWriter(tmp_path / "c.json", categories)


def test_missing_folder_and_extra(tmp_path, render, monkeypatch):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        CocoWriter(tmp_path / "missing" / "c.json", CATEGORIES)
    frame = render(_scene())
    monkeypatch.setitem(sys.modules, "pycocotools", None)
    with pytest.raises(ImportError, match=r"optional extra 'coco' \(pip install 'glphong\[coco\]'"):
        coco_annotations(frame, 1, "a.png")
