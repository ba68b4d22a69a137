"""BOP images as the frames of a batch: ``render_many(..., fmt='bop')``.

Each spec is one image of a BOP scene, ``out_dir/{scene_id:06d}/``, written as `glphong.datasets.write_bop` writes
one (its pieces: `glphong.datasets.bop.image_entries`, `render_image`, `image_files`, and the writing of
`glphong.datasets.bop_files`), so the files are the same byte for byte.  Which image a frame is:

- by default BlenderProc's and BOP's ``train_pbr`` layout: frame ``i`` is image ``i % frames_per_scene`` of scene
  ``i // frames_per_scene`` (``frames_per_scene`` default 1000, BlenderProc's ``frames_per_chunk``);
- or ``bop_ids``, one ``(scene_id, im_id)`` per spec (a real dataset's scenes: several views of one arrangement),
  each pair at most once.

The per-image files (``rgb/``, ``depth/``, ``mask/``, ``mask_visib/``) are written by the workers, each whole
(a temporary name, then ``os.replace``).  The three JSON files of a scene are the calling process's: a worker
returns the image's entries with the name, size and SHA-256 of each file it wrote, the parent journals them in
``frames.jsonl`` (one line an image, with a SHA-256 of the record itself) and writes a scene's
``scene_camera.json``, ``scene_gt.json`` and ``scene_gt_info.json`` (each whole, in the toolkit's layout) when
every image of the scene is done, and at the end of the batch, finished or not, for every scene folder there,
from the entries of the images done.  Workers never touch them, so parallel workers cannot lose or mix entries;
a rerun trusts an image where every file matches its record, renders the others again, and rewrites each JSON
file whose bytes differ, so a resumed batch ends with the files of an uninterrupted one.
"""
import hashlib
import json
import os
from functools import partial
from pathlib import Path

import numpy as np

from glphong.batch.folder import BatchError, _file_matches, _file_record, _regular_or_missing, _write_error
from glphong.core import validate as _validate
from glphong.datasets.bop import (DEFAULT_DEPTH_SCALE, MAX_BOP_ID, image_entries, image_files, obj_id_table,
                                  render_image)
from glphong.datasets.bop_files import (JSON_NAMES, image_folders, remove_masks_beyond, remove_temporaries,
                                        write_files, write_json_files)
from glphong.scene.scene import Scene

__all__ = ["FRAMES_PER_SCENE", "bop_settings", "BopImages", "bop_job"]

#: images per BOP scene by default: BlenderProc's ``frames_per_chunk`` and BOP's ``train_pbr`` scenes
FRAMES_PER_SCENE = 1000
_ARGUMENTS = ("bop_ids", "frames_per_scene", "obj_ids", "depth_scale", "count_truncated")


def bop_settings(fmt, count, width, height, options, bop_ids=None, frames_per_scene=None, obj_ids=None,
                 depth_scale=None, count_truncated=None):
    """`render_many`'s BOP arguments checked (every check before the folder is touched).

    Parameters
    ----------
    fmt : str
        The batch's format; the other arguments belong to ``'bop'`` only.
    count : int
        The number of specs.
    width, height : int
        The image size [px].
    options : dict
        The renderer options (``supersample`` is read).
    bop_ids, frames_per_scene, obj_ids, depth_scale, count_truncated
        As `glphong.batch.render_many` documents them.

    Returns
    -------
    dict or None
        None for another format; else ``{"ids": [(scene_id, im_id), ...] (one per spec), "obj_ids": dict,
        'category' or None, "depth_scale": float, "count_truncated": bool}``.

    Raises
    ------
    TypeError, ValueError
        A BOP argument with another format, both ``bop_ids`` and ``frames_per_scene``, ids out of range, not one
        per spec or repeated, a bad ``obj_ids``, ``depth_scale`` or ``count_truncated``, or a large canvas beyond
        the renderer's limit.
    """
    given = dict(zip(_ARGUMENTS, (bop_ids, frames_per_scene, obj_ids, depth_scale, count_truncated)))
    if fmt != "bop":
        named = [name for name, value in given.items() if value is not None]
        if named:
            raise ValueError(f"{', '.join(named)} belong to fmt='bop' (a batch writing BOP scenes); this batch's fmt "
                             f"is {fmt!r}")
        return None
    if bop_ids is not None and frames_per_scene is not None:
        raise ValueError("give bop_ids (each frame's (scene_id, im_id)) or frames_per_scene (frame i is image "
                         "i % frames_per_scene of scene i // frames_per_scene), not both")
    if bop_ids is None:
        per_scene = _validate.positive_int("frames_per_scene", FRAMES_PER_SCENE if frames_per_scene is None
                                           else frames_per_scene, 1, MAX_BOP_ID + 1)
        ids = [divmod(i, per_scene) for i in range(count)]
        if ids and ids[-1][0] > MAX_BOP_ID:
            raise ValueError(f"{count} frames at frames_per_scene={per_scene} reach scene_id {ids[-1][0]}, beyond "
                             f"{MAX_BOP_ID}: raise frames_per_scene")
    else:
        ids = _explicit_ids(bop_ids, count)
    depth_scale = _validate.scalar("depth_scale", DEFAULT_DEPTH_SCALE if depth_scale is None else depth_scale,
                                   low=0.0, low_inclusive=False)
    count_truncated = True if count_truncated is None else count_truncated
    if not isinstance(count_truncated, (bool, np.bool_)):
        raise TypeError(f"count_truncated must be a bool, True or False (got {count_truncated!r})")
    count_truncated = bool(count_truncated)
    supersample = options.get("supersample", 1)
    if count_truncated and isinstance(supersample, int) and 3 * max(width, height) * supersample > 16384:
        raise ValueError(f"count_truncated=True renders objects on a canvas three times the image's size "
                         f"({3 * width}x{3 * height}, supersample {supersample}), beyond the renderer's 16384 px: "
                         "pass count_truncated=False")
    return {"ids": ids, "obj_ids": obj_id_table(obj_ids), "depth_scale": depth_scale,
            "count_truncated": count_truncated}


def _explicit_ids(bop_ids, count):
    """``bop_ids`` checked: a list of ``(scene_id, im_id)`` int pairs, one per spec, each at most once."""
    if isinstance(bop_ids, (str, bytes)) or not hasattr(bop_ids, "__len__"):
        raise TypeError(f"bop_ids must be a sequence of (scene_id, im_id) pairs, one per spec (got "
                        f"{type(bop_ids).__name__})")
    if len(bop_ids) != count:
        raise ValueError(f"bop_ids must hold one (scene_id, im_id) pair per spec: {count} specs, {len(bop_ids)} "
                         "pairs")
    ids, seen = [], {}
    for i, pair in enumerate(bop_ids):
        if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise TypeError(f"bop_ids[{i}] must be a (scene_id, im_id) pair (got {pair!r})")
        scene_id = _validate.positive_int(f"bop_ids[{i}]'s scene_id", pair[0], 0, MAX_BOP_ID)
        im_id = _validate.positive_int(f"bop_ids[{i}]'s im_id", pair[1], 0, MAX_BOP_ID)
        if (scene_id, im_id) in seen:
            raise ValueError(f"bop_ids[{seen[scene_id, im_id]}] and bop_ids[{i}] are both image {im_id} of scene "
                             f"{scene_id}: each image is one frame's")
        seen[scene_id, im_id] = i
        ids.append((scene_id, im_id))
    return ids


def manifest_entry(settings):
    """What the manifest records of a BOP batch's settings (the ids by their SHA-256: a long list)."""
    ids = json.dumps([list(pair) for pair in settings["ids"]]).encode()
    table = settings["obj_ids"]
    if isinstance(table, dict):
        table = {str(k): v for k, v in sorted(table.items())}
    return {"ids_sha256": hashlib.sha256(ids).hexdigest()[:16], "depth_scale": settings["depth_scale"],
            "count_truncated": settings["count_truncated"], "obj_ids": table}


# -- in the worker ----------------------------------------------------------------------------------------------------

def bop_job(renderer, scene, index, out_dir, bop, large=None):
    """Render frame ``index`` as a BOP image with the worker's ``renderer`` (every check first); the job that
    encodes and writes its files, for the writer thread.

    Parameters
    ----------
    renderer : Renderer
    scene : Scene
        What ``scene_fn`` made of the frame's spec.
    index : int
    out_dir : str
    bop : dict
        ``{"ids": {index: (scene_id, im_id)}, "obj_ids", "depth_scale", "count_truncated"}``.
    large : callable, optional
        Returns the worker's renderer of the large canvas (`glphong.datasets.bop_masks.silhouettes`).

    Returns
    -------
    callable
        Taking no argument, returning ``(index, value)``: the image's journal value (`image_value`).
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene_fn must return a glphong Scene (got {type(scene).__name__})")
    scene_id, im_id = bop["ids"][index]
    camera, gt = image_entries(scene, renderer.width, renderer.height, bop["obj_ids"], bop["depth_scale"])
    frame, shapes = render_image(scene, renderer, bop["count_truncated"], large)
    return partial(_write_image, index, scene_id, im_id, out_dir, scene, frame, shapes, camera, gt,
                   bop["depth_scale"])


def _write_image(index, scene_id, im_id, out_dir, scene, frame, shapes, camera, gt, depth_scale):
    """Encode and write an image's files (each whole); ``(index, value)``, its journal value."""
    files, info = image_files(scene, frame, shapes, im_id, depth_scale, 1.0)
    root = os.path.join(out_dir, f"{scene_id:06d}")
    dirs = image_folders(root)
    for path in dirs.values():
        os.makedirs(path, exist_ok=True)
    try:
        write_files([(os.path.join(dirs[kind], name), data) for (kind, name), data in files.items()])
    except OSError as exc:
        raise _write_error(exc, os.path.join(dirs["rgb"], f"{im_id:06d}.png"), f"{sum(map(len, files.values()))} bytes",
                           f"image {im_id}'s {len(files)} files in {root}") from exc
    remove_masks_beyond(dirs, im_id, len(scene.objects))
    listed = [[f"{scene_id:06d}/{kind}/{name}", len(data), hashlib.sha256(data).hexdigest()]
              for (kind, name), data in files.items()]
    return index, image_value(listed, {"scene_camera": camera, "scene_gt": gt, "scene_gt_info": info})


def _digest(files, entries):
    text = json.dumps({"entries": entries, "files": files}, sort_keys=True, allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def image_value(files, entries):
    """A BOP image's journal value: ``{"size", "sha256", "files", "entries"}``.

    Parameters
    ----------
    files : list of [str, int, str]
        Each file written: its path relative to ``out_dir`` (``'000000/rgb/000007.png'``), size [bytes], SHA-256.
    entries : dict
        The image's ``scene_camera`` entry, ``scene_gt`` and ``scene_gt_info`` lists.

    Returns
    -------
    dict
        ``size`` the files' bytes together and ``sha256`` that of the record's files and entries (a record
        changed on disk no longer matches it).
    """
    return {"size": sum(size for _, size, _ in files), "sha256": _digest(files, entries), "files": files,
            "entries": entries}


def _expected_files(scene_id, im_id, count):
    im, root = f"{im_id:06d}", f"{scene_id:06d}"
    names = [f"{root}/rgb/{im}.png", f"{root}/depth/{im}.png"]
    for k in range(count):
        names += [f"{root}/mask/{im}_{k:06d}.png", f"{root}/mask_visib/{im}_{k:06d}.png"]
    return names


# -- in the calling process -------------------------------------------------------------------------------------------

class BopImages:
    """The frames of a ``fmt='bop'`` batch, as `glphong.batch.folder._BatchFolder` asks about them (its
    `glphong.batch.folder._FileFrames` says what for).

    Parameters
    ----------
    out : pathlib.Path
        The batch's folder.
    ids : list of (int, int)
        Each frame's ``(scene_id, im_id)``.
    """

    def __init__(self, out, ids):
        self.out, self.ids = Path(out), ids
        self.paths = [str(self.out / f"{s:06d}" / "rgb" / f"{i:06d}.png") for s, i in ids]
        self.scenes = {}
        for index, (scene_id, _) in enumerate(ids):
            self.scenes.setdefault(scene_id, []).append(index)
        for scene_id in self.scenes:
            root = self.out / f"{scene_id:06d}"
            for path in (root, *image_folders(root).values()):
                if os.path.lexists(path) and not os.path.isdir(path):
                    raise BatchError(f"{path} must be a folder of BOP scene {scene_id} (it exists and is not one): "
                                     "remove it or use another out_dir")

    def parse(self, index, record):
        """The value of journal ``record`` of frame ``index``: its files and entries checked, the files those
        of the frame's image, the record's SHA-256 its own; None otherwise."""
        files, entries = record.get("files"), record.get("entries")
        if not (isinstance(files, list) and isinstance(entries, dict) and set(entries) == set(JSON_NAMES)
                and isinstance(entries["scene_camera"], dict) and isinstance(entries["scene_gt"], list)
                and isinstance(entries["scene_gt_info"], list)
                and len(entries["scene_gt"]) == len(entries["scene_gt_info"])):
            return None
        if not all(isinstance(f, list) and len(f) == 3 and isinstance(f[0], str) and _file_record(f[1], f[2])
                   for f in files):
            return None
        if [f[0] for f in files] != _expected_files(*self.ids[index], len(entries["scene_gt"])):
            return None
        value = image_value(files, entries)
        return value if record.get("sha256") == value["sha256"] and record.get("size") == value["size"] else None

    def trusted(self, index, value):
        """Whether every file of frame ``index``'s image matches its record (None: no record); `BatchError` for a
        file that is a symbolic link or not regular."""
        if value is None:
            _regular_or_missing(self.paths[index], "a BOP image file")
            return False
        return all(_file_matches(str(self.out / name), size, sha256, "a BOP image file")
                   for name, size, sha256 in value["files"])

    def remove_partials(self):
        """Remove the temporary files writers that died left in the scene folders."""
        for scene_id in self.scenes:
            remove_temporaries(str(self.out / f"{scene_id:06d}"))

    def kept(self, value):
        """What the batch keeps in memory of an image journalled with ``value``: all of it (its scene's JSON files
        are written from the entries)."""
        return value

    def recorded(self, done, indices):
        """Write the JSON files of each scene of ``indices`` whose images are all ``done`` now."""
        for scene_id in sorted({self.ids[i][0] for i in indices}):
            if all(i in done for i in self.scenes[scene_id]):
                self._write_json(scene_id, done)

    def finish(self, done):
        """Write the JSON files of every scene folder there from the entries of its images ``done``."""
        for scene_id in self.scenes:
            if os.path.isdir(self.out / f"{scene_id:06d}"):
                self._write_json(scene_id, done)

    def _write_json(self, scene_id, done):
        images = {name: {} for name in JSON_NAMES}
        for index in self.scenes[scene_id]:
            if index in done:
                for name in JSON_NAMES:
                    images[name][self.ids[index][1]] = done[index]["entries"][name]
        write_json_files(str(self.out / f"{scene_id:06d}"), images)
