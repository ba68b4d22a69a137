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

The whole silhouettes are what one render per object alone (at the image's size, and on the large canvas) gives,
made from fewer renders (`glphong.datasets.bop_masks`: objects whose projected boxes are apart share one, an object
inside the image needs no large canvas).  The pieces `write_bop` is made of (`image_entries`, `render_image`,
`image_files`, and `glphong.datasets.bop_files`) also make the images of a batch (``render_many(..., fmt='bop')``,
`glphong.batch.bop_images`), so both write the same bytes.

Units: glphong's scenes are in metres; BOP's translations and depths are in millimetres, and its object models
(``models/obj_{obj_id:06d}.ply``) are in millimetres too: export each mesh scaled by 1000 for the model files
(`write_bop` writes the images, not the models).
"""
import os
import re
from collections.abc import Mapping

import numpy as np

from glphong.core import validate as _validate
from glphong.core.filesafety import SceneFileError
from glphong.core.imaging import png_bytes
from glphong.datasets.bop_files import check_entries, image_folders, json_text, load_json, same_camera, write_files
from glphong.datasets.bop_files import json_paths as _json_paths
from glphong.datasets.bop_masks import gt_info, silhouettes
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

def obj_id_table(obj_ids):
    """``obj_ids`` checked: a dict of instance_id (int) to BOP obj_id (int in [1, 2^31 - 1]), ``'category'`` or
    None.

    Raises
    ------
    TypeError
        Not a mapping or ``'category'``, or a key that is not an int.
    ValueError
        A value that is not an obj_id, or another string.
    """
    if obj_ids is None:
        return None
    if isinstance(obj_ids, str):
        if obj_ids != "category":
            raise ValueError(f"obj_ids must be a mapping of instance_id to BOP obj_id or 'category' (each object's "
                             f"category is its obj_id), got {obj_ids!r}")
        return obj_ids
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
    return table


def _object_ids(scene, obj_ids):
    """BOP's obj_id of each of ``scene.objects`` (list of int), from ``obj_ids`` (instance id to obj_id) or the
    instance ids."""
    instances = [int(o.instance_id) for o in scene.objects]
    table = obj_id_table(obj_ids)
    if table == "category":
        wrong = [(o.name, int(o.category)) for o in scene.objects if not 1 <= int(o.category) <= _MAX_OBJ_ID]
        if wrong:
            raise ValueError(f"obj_ids='category' makes each object's category its BOP obj_id, which must be in [1, "
                             f"{_MAX_OBJ_ID}]: object {wrong[0][0]!r} has category {wrong[0][1]}")
        return [int(o.category) for o in scene.objects]
    if table is None:
        too_big = [i for i in instances if i > _MAX_OBJ_ID]
        if too_big:
            raise ValueError(f"obj_ids is not given, so each object's instance_id is its BOP obj_id, and instance_id "
                             f"{too_big[0]} exceeds {_MAX_OBJ_ID}: pass obj_ids={{instance_id: obj_id}}")
        return instances
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


# -- one image: checked, rendered, encoded ----------------------------------------------------------------------------

def image_entries(scene, width, height, obj_ids, depth_scale):
    """The image's ``scene_camera`` entry and ``scene_gt`` list, every check of the scene made first.

    Parameters
    ----------
    scene : Scene
    width, height : int
        The image's size [px].
    obj_ids : mapping of int to int or None
        As `write_bop`'s.
    depth_scale : float
        [mm per unit of the depth PNG], checked.

    Returns
    -------
    camera : dict
        ``cam_K``, ``cam_R_w2c``, ``cam_t_w2c`` [mm], ``depth_scale``.
    gt : list of dict
        ``cam_R_m2c``, ``cam_t_m2c`` [mm], ``obj_id`` per object, in the order of ``scene.objects``.

    Raises
    ------
    TypeError, ValueError
        An orthographic or unknown camera, a pose that is not rigid, obj_ids that miss an object.
    """
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
    return camera_entry, gt


def render_image(scene, renderer, count_truncated, large=None):
    """The GPU's part of an image: the frame (radiance, depth, instance) and each object's whole silhouette
    (`glphong.datasets.bop_masks.silhouettes`; ``large`` as there).

    Returns
    -------
    frame : glphong.gpu.frame.Frame
    shapes : list of (inside, outside)
        Per object: ``inside`` (H, W) bool, ``outside`` ``(ys, xs)`` int64 [px] beyond the image.
    """
    frame = renderer.render(scene, passes=("radiance", "depth", "instance"))
    k = bop_camera_matrix(scene.camera, renderer.width, renderer.height)
    return frame, silhouettes(scene, renderer, k, bool(count_truncated), large, visible=frame.instance)


def image_files(scene, frame, shapes, im_id, depth_scale, exposure):
    """The CPU's part of an image: its PNG files' bytes and its ``scene_gt_info`` list.

    Parameters
    ----------
    scene : Scene
    frame, shapes
        From `render_image`.
    im_id : int
    depth_scale, exposure : float

    Returns
    -------
    files : dict of (str, str) to bytes
        ``(folder, file name)``: ``('rgb', '000007.png')``, ``('depth', ...)``, then ``('mask', '000007_000000.png')``
        and ``('mask_visib', ...)`` per object, in that order.
    info : list of dict
        The image's ``scene_gt_info`` entries, per object.

    Raises
    ------
    ValueError
        A depth the 16-bit PNG cannot hold at ``depth_scale``.
    """
    depth_units = depth_to_png_units(frame.depth, depth_scale)
    im = f"{im_id:06d}"
    files = {("rgb", f"{im}.png"): png_bytes(frame.radiance, exposure),
             ("depth", f"{im}.png"): encode_gray_png(depth_units)}
    info, blank = [], []
    for k, (obj, (inside, outside)) in enumerate(zip(scene.objects, shapes)):
        visible = frame.instance == obj.instance_id
        info.append(gt_info(inside, outside, visible, depth_units))
        whole = _mask_png(inside, blank)
        files[("mask", f"{im}_{k:06d}.png")] = whole
        files[("mask_visib", f"{im}_{k:06d}.png")] = whole if np.array_equal(visible, inside) else \
            _mask_png(visible, blank)
    return files, info


def _mask_png(mask, blank):
    """A mask's 8-bit PNG (255 inside, 0 outside); an empty mask's bytes are made once, in ``blank`` (a list): the
    same image gives the same bytes."""
    if mask.any():
        return encode_gray_png(mask.astype(np.uint8) * np.uint8(255))
    if not blank:
        blank.append(encode_gray_png(np.zeros(mask.shape, np.uint8)))
    return blank[0]


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
        Renders the image at its size (``renderer.width x renderer.height``).  With ``count_truncated``, where an
        object may reach beyond the image, it is resized to three times that size and back for the amodal
        silhouettes: do not share it with another thread during the call.
    scene_id, im_id : int
        0 to 999999.
    obj_ids : mapping of int to int, or 'category', optional
        Each object's BOP ``obj_id`` (>= 1) by its ``instance_id``; every object of the scene needs one (several
        instances may share an obj_id).  ``'category'``: each object's ``category`` (`glphong.Scene.add`) is its
        obj_id (BlenderProc's ``category_id``).  Default: the object's instance_id.
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
    camera_entry, gt = image_entries(scene, renderer.width, renderer.height, obj_ids, depth_scale)

    root = os.path.join(folder, f"{scene_id:06d}")
    dirs = image_folders(root)
    _check_not_files([folder, root, *dirs.values()])
    json_paths = _json_paths(root)
    stored = {}
    for name, path in json_paths.items():
        stored[name] = load_json(path)
        check_entries(path, stored[name], "camera" if name == "scene_camera" else "list")
    if im_id in stored["scene_camera"]:
        differ = same_camera(json_paths["scene_camera"], im_id, stored["scene_camera"][im_id], camera_entry)
        if differ:
            raise SceneFileError(json_paths["scene_camera"], f"im_id {im_id} is already written there with another "
                                 f"camera ({'; '.join(differ)}): write another im_id, or remove image {im_id} "
                                 "(its files and entries) first")

    # -- render, and everything derived, still before writing
    frame, shapes = render_image(scene, renderer, count_truncated)
    files, info = image_files(scene, frame, shapes, im_id, depth_scale, exposure)
    targets = [(os.path.join(dirs[kind], name), data) for (kind, name), data in files.items()]
    entries = {"scene_camera": camera_entry, "scene_gt": gt, "scene_gt_info": info}
    for name, images in stored.items():
        images[im_id] = entries[name]
        targets.append((json_paths[name], json_text(images).encode("utf-8")))

    # -- write: temporary files first, then the moves
    for path in dirs.values():
        os.makedirs(path, exist_ok=True)
    write_files(targets)
    # masks of objects beyond this image's count, from an earlier write of the same im_id, are no longer true
    count = len(scene.objects)
    for kind in ("mask", "mask_visib"):
        for entry in os.listdir(dirs[kind]):
            match = _MASK_NAME.match(entry)
            if match and int(match.group(1)) == im_id and int(match.group(2)) >= count:
                os.unlink(os.path.join(dirs[kind], entry))
    im = f"{im_id:06d}"
    return {"rgb": os.path.join(dirs["rgb"], f"{im}.png"), "depth": os.path.join(dirs["depth"], f"{im}.png"),
            "mask": [os.path.join(dirs["mask"], f"{im}_{k:06d}.png") for k in range(count)],
            "mask_visib": [os.path.join(dirs["mask_visib"], f"{im}_{k:06d}.png") for k in range(count)],
            **json_paths}
