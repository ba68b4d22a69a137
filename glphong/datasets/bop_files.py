"""The files of a BOP scene folder, as `glphong.datasets.bop` writes them: its three JSON files read, checked and
laid out as bop_toolkit's ``inout.save_json`` lays them out, and files written whole (a temporary name in the same
folder, then ``os.replace``).
"""
import json
import os
import re
import secrets

import numpy as np

from glphong.core.filesafety import SceneFileError, parse_json, read_bytes

__all__ = ["load_json", "check_entries", "same_camera", "json_text", "json_paths", "image_folders", "write_files",
           "write_json_files", "remove_masks_beyond", "remove_temporaries"]

#: what makes an image's camera: a rewrite of the image must keep them (its depth_scale may change: the depth image
#: is rewritten with it)
_CAMERA_KEYS = ("cam_K", "cam_R_w2c", "cam_t_w2c")
#: the scene's JSON files, by name
JSON_NAMES = ("scene_camera", "scene_gt", "scene_gt_info")


# -- the JSON files ---------------------------------------------------------------------------------------------------

def load_json(path):
    """The image dict of one of a scene's JSON files, ``{im_id (int): value}``; ``{}`` where the file does not
    exist; a `SceneFileError` for one that is not a regular file, is larger than ``LIMITS.file_bytes``, or is not
    JSON.  Keys are the im_id as a string (bop_toolkit ``inout.load_json(keys_to_int=True)``)."""
    if not os.path.lexists(path):
        return {}
    content = parse_json(path, read_bytes(path), "a BOP scene file")  # a regular file within Limits.file_bytes
    if not isinstance(content, dict):
        raise SceneFileError(path, f"expected a JSON object of im_id to entry (got a {type(content).__name__})")
    images = {}
    for key, value in content.items():
        if not (isinstance(key, str) and key.isdigit() and key.isascii()):
            raise SceneFileError(path, f"expected keys that are im_ids, non-negative integers (got {key!r})")
        if int(key) in images:
            raise SceneFileError(path, f"im_id {int(key)} appears twice (key {key!r})")
        images[int(key)] = value
    return images


def check_entries(path, images, kind):
    """Each image's entry of the file is of the right shape (a dict of the camera, or a list of dicts)."""
    for im_id, value in images.items():
        if kind == "camera":
            if not isinstance(value, dict):
                raise SceneFileError(path, f"expected a JSON object for each image (got a {type(value).__name__})",
                                     where=f'"{im_id}"')
        elif not (isinstance(value, list) and all(isinstance(v, dict) for v in value)):
            raise SceneFileError(path, "expected a list of JSON objects for each image", where=f'"{im_id}"')


def same_camera(path, im_id, old, new):
    """Whether the stored camera ``old`` of ``im_id`` is ``new``; the fields that differ otherwise (list of str)."""
    differ = []
    for key in _CAMERA_KEYS:
        if key not in old:
            differ.append(f"{key} (missing in the file)")
            continue
        want = np.atleast_1d(np.asarray(new[key], dtype=np.float64))
        try:
            have = np.atleast_1d(np.asarray(old[key], dtype=np.float64))
        except (TypeError, ValueError):
            raise SceneFileError(path, f"{key} must be numbers (got {old[key]!r})", where=f'"{im_id}"') from None
        if have.shape != want.shape:
            raise SceneFileError(path, f"{key} must hold {want.size} numbers (got {have.size})", where=f'"{im_id}"')
        if not np.allclose(have, want, rtol=1e-9, atol=1e-9):
            differ.append(f"{key} (file {have.tolist()}, now {want.tolist()})")
    return differ


def json_text(images):
    """The file's text as bop_toolkit ``inout.save_json`` writes a dict: one image a line, im_ids in increasing order,
    each value ``json.dumps(v, sort_keys=True)``."""
    lines = [f'  "{im_id}": {json.dumps(images[im_id], sort_keys=True, allow_nan=False)}' for im_id in sorted(images)]
    return "{\n" + ",\n".join(lines) + ("\n" if lines else "") + "}"


# -- writing ----------------------------------------------------------------------------------------------------------

_FOLDERS = ("rgb", "depth", "mask", "mask_visib")
#: the temporary files' names, ``.{name}.{16 hex digits}.tmp`` (`_write_temp`)
_TEMPORARY = re.compile(r"^\..+\.[0-9a-f]{16}\.tmp$")


def json_paths(root):
    """``{'scene_camera': root/scene_camera.json, 'scene_gt': ..., 'scene_gt_info': ...}`` of the scene folder."""
    return {name: os.path.join(root, f"{name}.json") for name in JSON_NAMES}


def image_folders(root):
    """``{'rgb': root/rgb, 'depth': ..., 'mask': ..., 'mask_visib': ...}`` of the scene folder ``root``."""
    return {name: os.path.join(root, name) for name in _FOLDERS}


def _write_temp(directory, name, data):
    """``data`` (bytes) in a new temporary file beside ``directory/name`` (a fresh name, opened exclusively, with
    the permissions any new file gets: the umask's); its path."""
    temp = os.path.join(directory, f".{name}.{secrets.token_hex(8)}.tmp")
    with open(temp, "xb") as handle:
        try:
            handle.write(data)
        except BaseException:
            handle.close()
            os.unlink(temp)
            raise
    return temp


def _remove(paths):
    for path in paths:
        try:
            os.unlink(path)
        except OSError:
            pass


def write_files(targets):
    """Write ``targets`` (a list of ``(path, bytes)``): every file to a temporary name in its folder first, then
    each moved into place (``os.replace``, atomic per file); a failure before the moves leaves no file changed, and
    no temporary file is left either way."""
    moves = []
    try:
        for target, data in targets:
            moves.append((_write_temp(os.path.dirname(target), os.path.basename(target), data), target))
    except BaseException:
        _remove(temp for temp, _ in moves)
        raise
    for i, (temp, target) in enumerate(moves):
        try:
            os.replace(temp, target)
        except BaseException:
            _remove(temp for temp, _ in moves[i:])
            raise


def remove_masks_beyond(dirs, im_id, count):
    """Remove image ``im_id``'s masks of objects ``count``, ``count + 1``, ... (from an earlier write of the image with
    more objects), up to the first index that has none."""
    k = count
    while True:
        paths = [os.path.join(dirs[kind], f"{im_id:06d}_{k:06d}.png") for kind in ("mask", "mask_visib")]
        found = [p for p in paths if os.path.lexists(p)]
        if not found:
            return
        _remove(found)
        k += 1


def remove_temporaries(root):
    """Remove the temporary files a writer killed mid-write left in the scene folder ``root`` and its image folders
    (named as `write_files` names them)."""
    for folder in (root, *image_folders(root).values()):
        try:
            names = os.listdir(folder)
        except OSError:
            continue
        _remove(os.path.join(folder, name) for name in names if _TEMPORARY.match(name))


def write_json_files(root, images):
    """Write a scene's JSON files from their entries, each only where its bytes differ from the file's.

    Parameters
    ----------
    root : str
        The scene folder (it exists).
    images : dict
        ``{'scene_camera': {im_id: entry}, 'scene_gt': {...}, 'scene_gt_info': {...}}``.

    Returns
    -------
    dict of str to str
        The paths of the three files.
    """
    paths = json_paths(root)
    targets = []
    for name, path in paths.items():
        data = json_text(images[name]).encode("utf-8")
        try:
            with open(path, "rb") as handle:
                same = handle.read(len(data) + 1) == data
        except OSError:
            same = False
        if not same:
            targets.append((path, data))
    write_files(targets)
    return paths
