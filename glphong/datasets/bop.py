"""One rendered frame written as an image of a BOP scene (the BOP 6D object pose benchmark's format).

`write_bop` renders the scene's radiance, depth and instance passes, and each object alone (its amodal silhouette),
and writes, under ``folder/{scene_id:06d}/``::

    rgb/{im_id:06d}.png                   8-bit sRGB
    depth/{im_id:06d}.png                 16-bit, depth [mm] / depth_scale
    mask/{im_id:06d}_{k:06d}.png          object k's whole silhouette (rendered alone), 255 inside, 0 outside
    mask_visib/{im_id:06d}_{k:06d}.png    the part of it that is visible in the image, 255 inside, 0 outside
    scene_camera.json                     per image: cam_K, cam_R_w2c, cam_t_w2c [mm], depth_scale
    scene_gt.json                         per image: a list of {cam_R_m2c, cam_t_m2c [mm], obj_id}
    scene_gt_info.json                    per image: a list of {bbox_obj, bbox_visib, px_count_all, px_count_valid,
                                          px_count_visib, visib_fract}

``k`` is the object's place in ``scene_gt.json``'s list for the image: the order of ``scene.objects``.

The conventions followed are the BOP toolkit's (github.com/thodan/bop_toolkit and its format page, bop_datasets_format.md):

- ``bop_toolkit_lib/inout.py``: ``save_json`` (keys the im_id as a string, sorted numerically, one image a line,
  each value ``json.dumps(v, sort_keys=True)``), ``save_scene_camera`` / ``save_scene_gt`` (matrices flattened
  row-major, ``cam_K.flatten()``, ``cam_R_*.flatten()``, translations as 3 numbers), ``save_depth``
  (``np.round(depth_mm / depth_scale).astype(np.uint16)``, a 16-bit greyscale PNG), ``load_depth`` (the PNG's
  values times ``depth_scale`` give mm).
- ``scripts/calc_gt_masks.py``: masks saved as ``255 * mask.astype(np.uint8)``; ``mask`` the object's silhouette
  rendered alone at its pose, ``mask_visib`` its visible part.
- ``scripts/calc_gt_info.py``: ``px_count_all`` the pixels of the whole silhouette *including the part outside the
  image* (the toolkit renders on a canvas three times the image's size, the image at its centre; so does
  `write_bop` unless ``count_truncated=False``), ``px_count_valid`` the silhouette's pixels in the image with a
  non-zero value in the depth image, ``px_count_visib`` the visible pixels, ``visib_fract = px_count_visib /
  px_count_all`` (0 when ``px_count_all`` is 0), ``bbox_obj`` the box of the whole silhouette (on the large canvas,
  in image coordinates, so possibly beyond the image) and ``bbox_visib`` of the visible part, both
  ``[-1, -1, -1, -1]`` where ``px_count_visib`` is 0.
- ``bop_toolkit_lib/misc.py`` ``calc_2d_bbox``: ``[x_min, y_min, x_max - x_min, y_max - y_min]`` over the pixels'
  integer coordinates (the width of a one-pixel box is 0), not clipped.

What differs from the toolkit, on purpose: the visible mask is exact (the instance pass: the pixels whose centre
sees the object), where the toolkit estimates it from depth with a 15 mm tolerance (``visibility.py``,
``estimate_visib_mask_gt``); it is what that estimate approximates.

Units: glphong's scenes are in metres; BOP's translations and depths are in millimetres, and its object models
(``models/obj_{obj_id:06d}.ply``) are in millimetres too: export each mesh scaled by 1000 for the model files
(`write_bop` writes the images, not the models).
"""
import json
import os
import re
import secrets
from collections.abc import Mapping

import numpy as np

from glphong.core import validate as _validate
from glphong.core.filesafety import SceneFileError
from glphong.core.imaging import png_bytes
from glphong.datasets.depth_png import depth_to_png_units, encode_gray_png
from glphong.gpu.passes import opencv_rotation
from glphong.gpu.renderer import Renderer
from glphong.scene.camera import IntrinsicsCamera, OrthographicCamera, PerspectiveCamera
from glphong.scene.scene import Scene

__all__ = ["write_bop", "bop_camera_matrix", "bop_world_to_camera", "bop_model_to_camera", "DEFAULT_DEPTH_SCALE",
           "MAX_BOP_ID"]

#: the default ``depth_scale`` [mm per unit of the depth PNG]: 0.1 mm steps, depths up to 6.5535 m (a table-top
#: scene's range); a scale BOP's datasets commonly record (YCB-V's, for one), and finer than the depth sensors the
#: benchmark's real images come from
DEFAULT_DEPTH_SCALE = 0.1
#: the largest scene_id or im_id: paths hold them in six digits (``{:06d}``)
MAX_BOP_ID = 999999
#: largest obj_id accepted (an int32 in every consumer)
_MAX_OBJ_ID = 2 ** 31 - 1
#: tolerance of the rigid-pose check: ``max |R^T R - I| <= 1e-6`` (a float32-made rotation passes; a scale of
#: 1.00001 does not)
_RIGID_TOL = 1e-6
#: what makes an image's camera: a rewrite of the image must keep them (its depth_scale may change: the depth image
#: is rewritten with it)
_CAMERA_KEYS = ("cam_K", "cam_R_w2c", "cam_t_w2c")
_MASK_NAME = re.compile(r"^(\d{6})_(\d{6})\.png$")


# -- cameras and poses ------------------------------------------------------------------------------------------------

def bop_camera_matrix(camera, width, height):
    """BOP's ``cam_K`` of a glphong camera rendering ``width x height`` images: OpenCV's intrinsic matrix, pixel
    centres at integers, that projects exactly as glphong does.

    Parameters
    ----------
    camera : PerspectiveCamera or IntrinsicsCamera
        An `OrthographicCamera` has no intrinsic matrix: refused.
    width, height : int
        The rendered image's size [px] (an `IntrinsicsCamera` rendered at another size of the same aspect has its
        intrinsics scaled).

    Returns
    -------
    (3, 3) float64 ndarray
        ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`` [px]: a point ``(X, Y, Z)`` of OpenCV's camera frame lands at
        ``u = fx X / Z + cx``, ``v = fy Y / Z + cy``.

    Notes
    -----
    From ``Camera._image_plane``: a `PerspectiveCamera` maps the pixel centre ``u + 0.5`` to ``x = (2 (u + 0.5) / W
    - 1) t W / H`` on the plane ``z = -1`` with ``t = tan(yfov / 2)``, so ``fx = fy = H / (2 t)``, ``cx = W / 2 -
    0.5``, ``cy = H / 2 - 0.5``.  An `IntrinsicsCamera` of size ``(w, h)`` rendered at ``W`` has ``s = w / W`` and
    ``fx' = fx / s``, ``cx' = (cx + 0.5) / s - 0.5`` (likewise in y).
    """
    width = _validate.positive_int("width", width, 1, 16384)
    height = _validate.positive_int("height", height, 1, 16384)
    if isinstance(camera, OrthographicCamera):
        raise ValueError("an OrthographicCamera cannot be written in BOP's format, whose cam_K is a pinhole's "
                         "intrinsic matrix: use a PerspectiveCamera or an IntrinsicsCamera")
    if isinstance(camera, IntrinsicsCamera):
        expected = camera.width / camera.height
        if abs(width / height - expected) > 1e-9 * expected:
            raise ValueError(f"the scene's IntrinsicsCamera belongs to {camera.width}x{camera.height} images; the "
                             f"renderer is {width}x{height}, another aspect: render at that aspect")
        sx, sy = camera.width / width, camera.height / height
        fx, fy = camera.fx / sx, camera.fy / sy
        cx, cy = (camera.cx + 0.5) / sx - 0.5, (camera.cy + 0.5) / sy - 0.5
    elif isinstance(camera, PerspectiveCamera):
        fx = fy = height / (2.0 * np.tan(camera.yfov / 2.0))
        cx, cy = width / 2.0 - 0.5, height / 2.0 - 0.5
    else:
        raise TypeError(f"the scene's camera must be a PerspectiveCamera or an IntrinsicsCamera to be written in "
                        f"BOP's format (got {type(camera).__name__})")
    return np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])


def _rigid(name, pose):
    """``pose`` (4, 4) float64 checked rigid: a rotation (``R^T R = I`` within `_RIGID_TOL`, det +1) and a finite
    translation, last row (0, 0, 0, 1)."""
    try:
        a = np.asarray(pose, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a finite (4, 4) array (got {type(pose).__name__}"
                         f"{'' if a is None else ' of shape ' + str(a.shape)})")
    r = a[:3, :3]
    error = float(np.max(np.abs(r.T @ r - np.eye(3))))
    if not (np.array_equal(a[3], (0.0, 0.0, 0.0, 1.0)) and error <= _RIGID_TOL and np.linalg.det(r) > 0.0):
        raise ValueError(f"{name} must be rigid, a rotation and a translation, for BOP's cam_R/cam_t: its 3x3 block "
                         f"has max |R^T R - I| = {error:.3g} (tolerance {_RIGID_TOL:g}) and determinant "
                         f"{np.linalg.det(r):.6g} (must be +1), last row {a[3].tolist()}; put any scale or mirror "
                         "into the mesh's vertices instead of the pose")
    return a


def bop_world_to_camera(camera):
    """BOP's ``cam_R_w2c`` and ``cam_t_w2c`` of a camera: world to OpenCV's camera frame (x right, y down, z forward).

    Returns
    -------
    rotation : (3, 3) float64 ndarray
        ``R_w2c = diag(1, -1, -1) R^T`` with ``R`` the camera pose's rotation (`glphong.gpu.passes.opencv_rotation`).
    translation : (3,) float64 ndarray
        ``t_w2c = -R_w2c c`` [mm], ``c`` the camera centre [m] times 1000.
    """
    _rigid("the scene's camera.pose", camera.pose)
    rotation = opencv_rotation(camera)
    return rotation + 0.0, 0.0 - 1000.0 * (rotation @ camera.pose[:3, 3])  # + 0.0: no -0.0 in the files


def bop_model_to_camera(camera, pose):
    """BOP's ``cam_R_m2c`` and ``cam_t_m2c`` of an object at ``pose`` (model to world, rigid) seen by ``camera``.

    Returns
    -------
    rotation : (3, 3) float64 ndarray
        ``R_m2c = R_w2c R_m2w``.
    translation : (3,) float64 ndarray
        ``t_m2c = R_w2c t_m2w [mm] + t_w2c`` [mm]: the model's origin in the camera frame.
    """
    r_w2c, t_w2c = bop_world_to_camera(camera)
    pose = _rigid("pose", pose)
    return r_w2c @ pose[:3, :3] + 0.0, r_w2c @ (1000.0 * pose[:3, 3]) + t_w2c + 0.0


# -- checks of the arguments ------------------------------------------------------------------------------------------

def _object_ids(scene, obj_ids):
    """BOP's obj_id of each of ``scene.objects`` (list of int), from ``obj_ids`` (instance id to obj_id) or the
    instance ids."""
    instances = [int(o.instance_id) for o in scene.objects]
    if obj_ids is None:
        too_big = [i for i in instances if i > _MAX_OBJ_ID]
        if too_big:
            raise ValueError(f"obj_ids is not given, so each object's instance_id is its BOP obj_id, and instance_id "
                             f"{too_big[0]} exceeds {_MAX_OBJ_ID}: pass obj_ids={{instance_id: obj_id}}")
        return instances
    if not isinstance(obj_ids, Mapping):
        raise TypeError(f"obj_ids must be a mapping of instance_id to BOP obj_id, e.g. {{1: 5, 2: 5}} (got "
                        f"{type(obj_ids).__name__})")
    table = {}
    for key, value in obj_ids.items():
        if isinstance(key, bool) or not isinstance(key, (int, np.integer)):
            raise TypeError(f"obj_ids' keys must be instance ids, int (got {key!r})")
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= int(value) <= _MAX_OBJ_ID:
            raise ValueError(f"obj_ids[{key!r}] must be a BOP obj_id, an int in [1, {_MAX_OBJ_ID}] (got {value!r})")
        table[int(key)] = int(value)
    missing = [(o.name, i) for o, i in zip(scene.objects, instances) if i not in table]
    if missing:
        listed = ", ".join(f"{name!r} (instance_id {i})" for name, i in missing)
        raise ValueError(f"obj_ids must give a BOP obj_id for every object of the scene; it has none for {listed}")
    return [table[i] for i in instances]


def _folder(folder):
    if isinstance(folder, bytes) or not isinstance(folder, (str, os.PathLike)):
        raise TypeError(f"folder must be a path, str or os.PathLike (got {type(folder).__name__})")
    folder = os.fspath(folder)
    if folder == "":
        raise ValueError("folder must be a path to a folder (got '')")
    return folder


def _check_not_files(paths):
    """Refuse where a folder ``write_bop`` needs is a file (or something else that is not a folder)."""
    for path in paths:
        if os.path.lexists(path) and not os.path.isdir(path):
            raise ValueError(f"{path} must be a folder (it exists and is not one): choose another folder")


# -- the JSON files ---------------------------------------------------------------------------------------------------

def _load_json(path):
    """The image dict of one of a scene's JSON files, ``{im_id (int): value}``; ``{}`` where the file does not
    exist.  Keys are the im_id as a string (bop_toolkit ``inout.load_json(keys_to_int=True)``)."""
    if not os.path.lexists(path):
        return {}
    if not os.path.isfile(path):
        raise SceneFileError(path, "expected a BOP JSON file, found something that is not a regular file")
    try:
        with open(path, encoding="utf-8") as handle:
            content = json.load(handle)
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise SceneFileError(path, f"not readable as JSON ({exc}); fix or remove the file") from None
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


def _check_entries(path, images, kind):
    """Each image's entry of the file is of the right shape (a dict of the camera, or a list of dicts)."""
    for im_id, value in images.items():
        if kind == "camera":
            if not isinstance(value, dict):
                raise SceneFileError(path, f"expected a JSON object for each image (got a {type(value).__name__})",
                                     where=f'"{im_id}"')
        elif not (isinstance(value, list) and all(isinstance(v, dict) for v in value)):
            raise SceneFileError(path, "expected a list of JSON objects for each image", where=f'"{im_id}"')


def _same_camera(path, im_id, old, new):
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


def _json_text(images):
    """The file's text as bop_toolkit ``inout.save_json`` writes a dict: one image a line, im_ids in increasing order,
    each value ``json.dumps(v, sort_keys=True)``."""
    lines = [f'  "{im_id}": {json.dumps(images[im_id], sort_keys=True, allow_nan=False)}' for im_id in sorted(images)]
    return "{\n" + ",\n".join(lines) + ("\n" if lines else "") + "}"


# -- the masks and their numbers --------------------------------------------------------------------------------------

def _bbox(ys, xs):
    """bop_toolkit ``misc.calc_2d_bbox(xs, ys)`` (clip=False): ``[x_min, y_min, x_max - x_min, y_max - y_min]``."""
    x0, y0 = int(xs.min()), int(ys.min())
    return [x0, y0, int(xs.max()) - x0, int(ys.max()) - y0]


def _alone(scene, obj, camera=None):
    """A scene of ``scene``'s camera (or ``camera``) and lights holding ``obj`` alone, as it is."""
    single = Scene(scene.camera if camera is None else camera, scene.lights, scene.ambient)
    single.add(obj.mesh, obj.material, pose=obj.pose, name=obj.name, casts_shadow=obj.casts_shadow,
               instance_id=obj.instance_id, category=obj.category)
    return single


def _silhouettes(scene, renderer, count_truncated):
    """Each object's silhouette rendered alone: ``(inside, outside)`` per object, ``inside`` (H, W) bool the
    image's pixels, ``outside`` ``(ys, xs)`` int arrays of the pixels beyond the image on a canvas three times its
    size (bop_toolkit ``calc_gt_info.py``), empty without ``count_truncated``."""
    width, height = renderer.width, renderer.height
    inside = [renderer.render(_alone(scene, obj), passes=("instance",)).instance != 0 for obj in scene.objects]
    empty = (np.zeros(0, np.int64), np.zeros(0, np.int64))
    if not count_truncated or not scene.objects:
        return [(m, empty) for m in inside]
    if 3 * max(width, height) * renderer.supersample > 16384:
        raise ValueError(f"count_truncated=True renders each object on a canvas three times the image's size "
                         f"({3 * width}x{3 * height}), beyond the renderer's 16384 px (supersample "
                         f"{renderer.supersample}): pass count_truncated=False (px_count_all and bbox_obj then count "
                         "the image's pixels only)")
    k = bop_camera_matrix(scene.camera, width, height)
    large = IntrinsicsCamera(k[0, 0], k[1, 1], k[0, 2] + width, k[1, 2] + height, 3 * width, 3 * height,
                             pose=scene.camera.pose, znear=scene.camera.znear, zfar=scene.camera.zfar)
    out = []
    renderer.resize(3 * width, 3 * height)
    try:
        for obj, mask in zip(scene.objects, inside):
            big = renderer.render(_alone(scene, obj, large), passes=("instance",)).instance != 0
            big[height:2 * height, width:2 * width] = False  # the image's own pixels come from the exact render
            ys, xs = np.nonzero(big)
            out.append((mask, (ys - height, xs - width)))
    finally:
        renderer.resize(width, height)
    return out


def _gt_info(inside, outside, visible, depth_units):
    """One object's ``scene_gt_info`` entry (bop_toolkit ``scripts/calc_gt_info.py``)."""
    px_count_all = int(inside.sum()) + int(outside[0].size)
    px_count_valid = int(np.count_nonzero(depth_units[inside]))
    px_count_visib = int(visible.sum())
    bbox_obj = bbox_visib = [-1, -1, -1, -1]
    if px_count_visib > 0:  # the toolkit gives both boxes only where something is visible
        ys, xs = np.nonzero(inside)
        bbox_obj = _bbox(np.concatenate([ys, outside[0]]), np.concatenate([xs, outside[1]]))
        bbox_visib = _bbox(*np.nonzero(visible))
    return {"bbox_obj": bbox_obj, "bbox_visib": bbox_visib, "px_count_all": px_count_all,
            "px_count_valid": px_count_valid, "px_count_visib": px_count_visib,
            "visib_fract": px_count_visib / float(px_count_all) if px_count_all > 0 else 0.0}


# -- writing ----------------------------------------------------------------------------------------------------------

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


def write_bop(folder, scene, renderer, scene_id=0, im_id=0, obj_ids=None, *, depth_scale=DEFAULT_DEPTH_SCALE,
              exposure=1.0, count_truncated=True):
    """Render ``scene`` and write it as image ``im_id`` of BOP scene ``scene_id`` under ``folder``.

    Writes ``folder/{scene_id:06d}/rgb/{im_id:06d}.png``, ``depth/{im_id:06d}.png``, ``mask/{im_id:06d}_{k:06d}.png``
    and ``mask_visib/{im_id:06d}_{k:06d}.png`` for each object ``k`` (its index in ``scene.objects``: its place in
    ``scene_gt.json``'s list), and adds (or replaces) the image's entry in ``scene_camera.json``, ``scene_gt.json``
    and ``scene_gt_info.json`` (the module docstring: what each holds and the BOP toolkit code it follows).  Other
    images' entries are kept; writing the same image again with the same camera rewrites it (idempotent).

    Nothing is written half: every check and render comes first; then each file is written under a temporary name
    in its own folder and moved into place (``os.replace``, atomic per file); a failure before the moves leaves the
    folder as it was.

    Parameters
    ----------
    folder : str or os.PathLike
        The BOP split's folder (e.g. ``.../test``); created if missing.
    scene : Scene
        Seen by a `PerspectiveCamera` or `IntrinsicsCamera` (an `OrthographicCamera` has no BOP equivalent); every
        object's pose rigid (rotation and translation, no scale or shear).  Scene units are metres.
    renderer : Renderer
        Renders the image at its size (``renderer.width x renderer.height``).  With ``count_truncated`` it is
        resized to three times that size and back for the amodal silhouettes: do not share it with another thread
        during the call.
    scene_id, im_id : int
        0 to 999999.
    obj_ids : mapping of int to int, optional
        Each object's BOP ``obj_id`` (>= 1) by its ``instance_id``; every object of the scene needs one (several
        instances may share an obj_id).  Default: the object's instance_id.
    depth_scale : float
        Millimetres per unit of the 16-bit depth PNG, recorded in ``scene_camera.json`` (default 0.1: 0.1 mm steps
        up to 6.5535 m, a scale BOP's datasets commonly use).  A depth beyond ``65535 depth_scale`` mm is an
        error naming the scale that would hold it.
    exposure : float
        The linear exposure of the 8-bit sRGB ``rgb`` image (`glphong.gpu.frame.Frame.save_png`), default 1.
    count_truncated : bool
        True (default, the toolkit's ``calc_gt_info.py``): ``px_count_all`` and ``bbox_obj`` count the object's
        silhouette beyond the image too, from a render on a canvas three times the image's size.  False: the
        image's pixels only (cheaper; ``visib_fract`` then overstates the visible fraction of cut-off objects).

    Returns
    -------
    dict
        The paths written: ``'rgb'``, ``'depth'`` (str), ``'mask'``, ``'mask_visib'`` (list of str, one per object),
        ``'scene_camera'``, ``'scene_gt'``, ``'scene_gt_info'`` (str).

    Raises
    ------
    TypeError
        An argument of the wrong type (which one named).
    ValueError
        A bad id, an obj_ids that misses an object or maps it to an id < 1, a pose that is not rigid, an
        orthographic camera, a depth the 16-bit PNG cannot hold at ``depth_scale``, a folder that is a file.
    glphong.core.filesafety.SceneFileError
        (a ValueError) An existing JSON file of the scene that is malformed, or whose ``scene_camera.json``
        holds ``im_id`` with another camera (remove that image, or write another im_id).
    """
    # -- every check before anything is rendered or written
    folder = _folder(folder)
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a glphong Scene (got {type(scene).__name__})")
    if not isinstance(renderer, Renderer):
        raise TypeError(f"renderer must be a glphong Renderer (got {type(renderer).__name__})")
    scene_id = _validate.positive_int("scene_id", scene_id, 0, MAX_BOP_ID)
    im_id = _validate.positive_int("im_id", im_id, 0, MAX_BOP_ID)
    depth_scale = _validate.scalar("depth_scale", depth_scale, low=0.0, low_inclusive=False)
    exposure = _validate.scalar("exposure", exposure, low=0.0, low_inclusive=False)
    if not isinstance(count_truncated, (bool, np.bool_)):
        raise TypeError(f"count_truncated must be a bool, True or False (got {count_truncated!r})")
    width, height = renderer.width, renderer.height
    cam_k = bop_camera_matrix(scene.camera, width, height)
    r_w2c, t_w2c = bop_world_to_camera(scene.camera)
    ids = _object_ids(scene, obj_ids)
    gt = []
    for obj, obj_id in zip(scene.objects, ids):
        _rigid(f"the pose of object {obj.name!r} (instance_id {obj.instance_id})", obj.pose)
        r_m2c, t_m2c = bop_model_to_camera(scene.camera, obj.pose)
        gt.append({"cam_R_m2c": r_m2c.flatten().tolist(), "cam_t_m2c": t_m2c.tolist(), "obj_id": obj_id})
    camera_entry = {"cam_K": cam_k.flatten().tolist(), "cam_R_w2c": r_w2c.flatten().tolist(),
                    "cam_t_w2c": t_w2c.tolist(), "depth_scale": depth_scale}

    root = os.path.join(folder, f"{scene_id:06d}")
    dirs = {name: os.path.join(root, name) for name in ("rgb", "depth", "mask", "mask_visib")}
    _check_not_files([folder, root, *dirs.values()])
    json_paths = {name: os.path.join(root, f"{name}.json") for name in ("scene_camera", "scene_gt", "scene_gt_info")}
    stored = {}
    for name, path in json_paths.items():
        stored[name] = _load_json(path)
        _check_entries(path, stored[name], "camera" if name == "scene_camera" else "list")
    if im_id in stored["scene_camera"]:
        differ = _same_camera(json_paths["scene_camera"], im_id, stored["scene_camera"][im_id], camera_entry)
        if differ:
            raise SceneFileError(json_paths["scene_camera"], f"im_id {im_id} is already written there with another "
                                 f"camera ({'; '.join(differ)}): write another im_id, or remove image {im_id} "
                                 "(its files and entries) first")

    # -- render, and everything derived, still before writing
    frame = renderer.render(scene, passes=("radiance", "depth", "instance"))
    depth_units = depth_to_png_units(frame.depth, depth_scale)
    silhouettes = _silhouettes(scene, renderer, bool(count_truncated))
    info, payloads = [], {}
    im = f"{im_id:06d}"
    payloads[("rgb", f"{im}.png")] = png_bytes(frame.radiance, exposure)
    payloads[("depth", f"{im}.png")] = encode_gray_png(depth_units)
    for k, (obj, (inside, outside)) in enumerate(zip(scene.objects, silhouettes)):
        visible = frame.instance == obj.instance_id
        info.append(_gt_info(inside, outside, visible, depth_units))
        payloads[("mask", f"{im}_{k:06d}.png")] = encode_gray_png(inside.astype(np.uint8) * np.uint8(255))
        payloads[("mask_visib", f"{im}_{k:06d}.png")] = encode_gray_png(visible.astype(np.uint8) * np.uint8(255))
    entries = {"scene_camera": camera_entry, "scene_gt": gt, "scene_gt_info": info}
    for name, images in stored.items():
        images[im_id] = entries[name]
        payloads[(None, json_paths[name])] = _json_text(images).encode("utf-8")

    # -- write: temporary files first, then the moves
    for path in dirs.values():
        os.makedirs(path, exist_ok=True)
    moves = []
    try:
        for (kind, name), data in payloads.items():
            target = name if kind is None else os.path.join(dirs[kind], name)
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
    # masks of objects beyond this image's count, from an earlier write of the same im_id, are no longer true
    count = len(scene.objects)
    for kind in ("mask", "mask_visib"):
        for entry in os.listdir(dirs[kind]):
            match = _MASK_NAME.match(entry)
            if match and int(match.group(1)) == im_id and int(match.group(2)) >= count:
                os.unlink(os.path.join(dirs[kind], entry))
    return {"rgb": os.path.join(dirs["rgb"], f"{im}.png"), "depth": os.path.join(dirs["depth"], f"{im}.png"),
            "mask": [os.path.join(dirs["mask"], f"{im}_{k:06d}.png") for k in range(count)],
            "mask_visib": [os.path.join(dirs["mask_visib"], f"{im}_{k:06d}.png") for k in range(count)],
            **json_paths}
