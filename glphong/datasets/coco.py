"""Instance segmentation in COCO's JSON (the optional extra ``coco``: pycocotools >= 2.0.7).

`coco_annotations` turns one frame's ``instance`` and ``category`` passes into COCO's ``images`` entry and one
``annotations`` entry per object seen; `CocoWriter` gathers many frames into one file that
``pycocotools.coco.COCO(path)`` reads.

Each annotation is the object's visible pixels (occluders hide what they cover; ``frame.instance == id`` at the
pixel centres, one sample per pixel):

- ``segmentation``: COCO's compressed RLE, made by ``pycocotools.mask.encode`` from the Fortran-ordered uint8 mask,
  ``{"size": [H, W], "counts": str}`` (the counts decoded from bytes so that it is JSON); ``iscrowd`` 0;
- ``area``: the pixel count (``pycocotools.mask.area``);
- ``bbox``: ``[x, y, width, height]`` in pixels, x right and y down from the image's top-left corner
  (``pycocotools.mask.toBbox``: the box of the covered pixels, whole numbers);
- ``category_id``: the object's ``Scene.add(..., category=)``, read from the ``category`` pass.

Annotation ids: the annotations of a frame are numbered in increasing instance id, from ``first_annotation_id``
(default 1) for `coco_annotations`; a `CocoWriter` numbers all its annotations 1, 2, 3 ... in the order the
frames are added, so they are unique in the file.  The instance id itself is kept as ``instance_id`` in each
annotation (an extra key COCO's readers ignore) for matching with the other passes.

Category 0 is glphong's background (and no COCO category: COCO's ids start at 1).  An object seen with category 0
(``Scene.add`` without ``category=``) is an error by default, since a COCO file whose object has no class is
rarely what was meant; ``unlabelled='skip'`` leaves such objects out (distractors), and they are then
background to COCO's evaluation.
"""
import json
import numbers
from pathlib import Path

import numpy as np

from glphong.core.version import __version__
from glphong.core.atomic_files import write_atomically

__all__ = ["coco_annotations", "CocoWriter"]

_UNLABELLED = ("error", "skip")


def _pycocotools_mask():
    try:
        from pycocotools import mask  # noqa: PLC0415 - the optional extra
    except ImportError:
        raise ImportError("COCO annotations need the optional extra 'coco' (pip install 'glphong[coco]', which "
                          "installs pycocotools)") from None
    return mask


def _id(what, value, low):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise ValueError(f"{what} must be an integer >= {low} (got {value!r})")
    return int(value)


def _file_name(file_name):
    if not isinstance(file_name, str) or not file_name or "\x00" in file_name:
        raise ValueError(f"file_name must be a non-empty str, the image's path as the dataset names it "
                         f"(got {file_name!r:.80})")
    return file_name


def _id_passes(frame):
    """``(instance, category)`` of ``frame``, (H, W) uint32 each, or a ValueError naming the missing pass."""
    held = getattr(frame, "passes", None)
    if held is None or isinstance(held, str):
        raise TypeError(f"expected a glphong Frame (renderer.render(...)), got {type(frame).__name__}")
    arrays = []
    for name in ("instance", "category"):
        value = getattr(frame, name, None)
        if name not in held or value is None:
            raise ValueError(f"COCO annotations need the {name!r} pass, and the frame holds {list(held)}: render with "
                             "passes=(..., 'instance', 'category')")
        value = np.asarray(value)
        if value.dtype != np.uint32 or value.ndim != 2 or 0 in value.shape:
            raise ValueError(f"frame.{name} is {value.dtype} {value.shape}; expected uint32 (H, W)")
        arrays.append(value)
    if arrays[0].shape != arrays[1].shape:
        raise ValueError(f"frame.instance is {arrays[0].shape} and frame.category {arrays[1].shape}; expected one size")
    return arrays


def coco_annotations(frame, image_id, file_name, first_annotation_id=1, unlabelled="error"):
    """COCO's ``images`` entry and ``annotations`` of one frame (module docstring: the fields and the ids).

    Parameters
    ----------
    frame : glphong.gpu.frame.Frame
        A render holding the ``instance`` and ``category`` passes, (H, W) uint32 each.
    image_id : int
        The image's id (>= 0), unique in the dataset.
    file_name : str
        The image's file as the dataset names it (e.g. ``"images/000012.png"``).
    first_annotation_id : int
        Id of the first annotation (>= 1); the others follow by one, in increasing instance id.
    unlabelled : {'error', 'skip'}
        What an object seen with category 0 gives: a ValueError (default) or no annotation.

    Returns
    -------
    dict
        ``{"images": [{"id", "file_name", "width", "height"}], "annotations": [{"id", "image_id", "category_id",
        "segmentation": {"size": [H, W], "counts": str}, "area", "bbox": [x, y, w, h], "iscrowd": 0,
        "instance_id"}, ...]}``, plain JSON types.

    Raises
    ------
    ImportError
        pycocotools is not installed (the extra 'coco').
    ValueError
        The frame lacks the ``instance`` or ``category`` pass, an object is seen with category 0 (with
        ``unlabelled='error'``) or with two categories, or an argument is out of range.
    """
    mask_api = _pycocotools_mask()
    image_id = _id("image_id", image_id, 0)
    file_name = _file_name(file_name)
    next_id = _id("first_annotation_id", first_annotation_id, 1)
    if unlabelled not in _UNLABELLED:
        raise ValueError(f"unlabelled must be one of {_UNLABELLED} (got {unlabelled!r})")
    instance, category = _id_passes(frame)
    height, width = instance.shape
    ids, first = np.unique(instance, return_index=True)
    objects = ids != 0
    ids, first = ids[objects], first[objects]
    categories = category.reshape(-1)[first]
    annotations = []
    for object_id, category_id in zip(ids.tolist(), categories.tolist()):
        seen = instance == object_id
        other = np.unique(category[seen])
        if other.size != 1:
            raise ValueError(f"{file_name}: instance {object_id} is seen with categories {other.tolist()}; expected "
                             "one per object")
        if category_id == 0:
            if unlabelled == "skip":
                continue
            raise ValueError(f"{file_name}: instance {object_id} is seen with category 0 (glphong's background, no "
                             "COCO category): give the object its class with Scene.add(..., category=) (ids from 1), "
                             "or pass unlabelled='skip' to leave such objects out")
        rle = mask_api.encode(np.asfortranarray(seen, dtype=np.uint8))
        bbox = mask_api.toBbox(rle)
        annotations.append({
            "id": next_id, "image_id": image_id, "category_id": int(category_id),
            "segmentation": {"size": [int(v) for v in rle["size"]], "counts": rle["counts"].decode("ascii")},
            "area": int(mask_api.area(rle)), "bbox": [float(v) for v in bbox], "iscrowd": 0,
            "instance_id": int(object_id),
        })
        next_id += 1
    image = {"id": image_id, "file_name": file_name, "width": int(width), "height": int(height)}
    return {"images": [image], "annotations": annotations}


def _categories(categories):
    """COCO's ``categories`` list from ``{id: name}`` or a list of COCO's category dicts, checked."""
    if isinstance(categories, dict):
        entries = [{"id": key, "name": value} for key, value in categories.items()]
    elif isinstance(categories, (list, tuple)):
        entries = []
        for i, entry in enumerate(categories):
            if not isinstance(entry, dict) or "id" not in entry or "name" not in entry:
                raise ValueError(f"categories[{i}] must be a dict with 'id' and 'name' (COCO's category), got "
                                 f"{entry!r:.80}")
            entries.append(dict(entry))
    else:
        raise TypeError(f"categories must be a dict {{id: name}} or a list of COCO category dicts (got "
                        f"{type(categories).__name__})")
    out, seen = [], set()
    for entry in entries:
        category_id = _id("a category id", entry["id"], 1)
        if category_id in seen:
            raise ValueError(f"category id {category_id} is listed twice")
        if not isinstance(entry["name"], str) or not entry["name"]:
            raise ValueError(f"category {category_id}: its name must be a non-empty str (got {entry['name']!r:.80})")
        seen.add(category_id)
        out.append({**entry, "id": category_id, "supercategory": entry.get("supercategory", entry["name"])})
    if not out:
        raise ValueError("categories is empty: a COCO file lists the classes its annotations use")
    try:
        json.dumps(out, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"categories must be plain JSON values ({exc})") from None
    return sorted(out, key=lambda e: e["id"])


class CocoWriter:
    """Gathers frames' instance segmentations into one COCO JSON file (module docstring: the fields and the ids).

    Parameters
    ----------
    path : path-like
        The JSON file `write` makes (its folder must exist); replaced whole or not at all.
    categories : dict of int to str, or list of dict
        The classes: ``{category_id: name}``, or COCO's list of ``{"id", "name", "supercategory"}`` dicts; ids
        >= 1, the values of ``Scene.add(..., category=)``.
    unlabelled : {'error', 'skip'}
        What an object seen with category 0 gives (`coco_annotations`).
    info : dict, optional
        COCO's ``info`` (default: a description naming glphong and its version).

    Examples
    --------
    >>> with CocoWriter("out/annotations.json", {1: "mug", 2: "bowl"}) as coco:   # doctest: +SKIP
    ...     for i, scene in enumerate(scenes):
    ...         frame = renderer.render(scene, passes=("radiance", "instance", "category"))
    ...         frame.save_png(f"out/{i:06d}.png")
    ...         coco.add(frame, f"{i:06d}.png")

    The file is written when the ``with`` block ends without an exception (or by `write`); after an exception
    nothing is written.
    """

    def __init__(self, path, categories, unlabelled="error", info=None):
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise FileNotFoundError(f"{self.path}: the folder {self.path.parent} does not exist")
        if unlabelled not in _UNLABELLED:
            raise ValueError(f"unlabelled must be one of {_UNLABELLED} (got {unlabelled!r})")
        self.unlabelled = unlabelled
        self.categories = _categories(categories)
        self.info = dict(info) if info is not None else {"description": f"rendered with glphong {__version__}",
                                                          "version": __version__}
        self.images, self.annotations = [], []
        self._image_ids, self._file_names = set(), set()

    def add(self, frame, file_name, image_id=None):
        """Add a frame's image and its objects' annotations.

        Parameters
        ----------
        frame : glphong.gpu.frame.Frame
            With the ``instance`` and ``category`` passes.
        file_name : str
            The image's file as the dataset names it; unique in the file.
        image_id : int, optional
            Unique in the file; default one more than the largest so far (1 for the first).

        Returns
        -------
        int
            The image id.

        Raises
        ------
        ValueError
            A duplicate image id or file name, a category id not in ``categories`` (named), or what
            `coco_annotations` raises.  The writer is left as it was.
        """
        file_name = _file_name(file_name)
        if image_id is None:
            image_id = max(self._image_ids, default=0) + 1
        image_id = _id("image_id", image_id, 0)
        if image_id in self._image_ids:
            raise ValueError(f"{file_name}: image id {image_id} is already in {self.path.name}; image ids are unique")
        if file_name in self._file_names:
            raise ValueError(f"{file_name}: this file name is already in {self.path.name}; file names are unique")
        entry = coco_annotations(frame, image_id, file_name, len(self.annotations) + 1, self.unlabelled)
        known = {c["id"] for c in self.categories}
        unknown = sorted({a["category_id"] for a in entry["annotations"]} - known)
        if unknown:
            raise ValueError(f"{file_name}: category ids {unknown} are not in the writer's categories "
                             f"{sorted(known)}: add them to CocoWriter(path, categories)")
        self.images.extend(entry["images"])
        self.annotations.extend(entry["annotations"])
        self._image_ids.add(image_id)
        self._file_names.add(file_name)
        return image_id

    def dataset(self):
        """The COCO dataset so far: a dict with ``info``, ``images``, ``annotations`` and ``categories``."""
        return {"info": self.info, "images": list(self.images), "annotations": list(self.annotations),
                "categories": list(self.categories)}

    def write(self):
        """Write the file atomically (a temporary file renamed over ``path``); its path.

        Raises
        ------
        ValueError
            ``info`` is not plain JSON.
        """
        try:
            text = json.dumps(self.dataset(), allow_nan=False, separators=(",", ":"))
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{self.path}: the dataset is not plain JSON ({exc})") from None

        def write(temporary):
            with open(temporary, "w", encoding="utf-8") as stream:
                stream.write(text)

        return write_atomically(self.path, write)

    def __enter__(self):
        return self

    def __exit__(self, kind, value, traceback):
        if kind is None:
            self.write()
        return False

    def __repr__(self):
        return (f"CocoWriter({str(self.path)!r}, {len(self.categories)} categories, {len(self.images)} images, "
                f"{len(self.annotations)} annotations)")

