"""The whole (amodal) silhouettes behind BOP's ``mask/`` images and ``scene_gt_info.json`` (`glphong.datasets.bop`).

An object's whole silhouette is what the instance pass shows where the object is rendered alone: at the image's
size (its ``mask``), and on a canvas three times that size with the image at its centre for the pixels cut off by
the image's border (``px_count_all`` and ``bbox_obj`` count them, as bop_toolkit's ``scripts/calc_gt_info.py``
does).  Rendering each object alone, twice, is what an image cost; `silhouettes` gives the same pixels, exactly,
from fewer renders:

- **A conservative box per object.**  The mesh's vertices, posed, in the camera's frame (metres) and, where all
  lie at least ``znear / 2`` in front of the camera, through ``cam_K`` (`glphong.datasets.bop.bop_camera_matrix`,
  which projects as glphong does): a triangle in front of the camera projects to the triangle of its vertices'
  projections, and every piece the clipper cuts from it lies inside it, so a pixel whose centre lies outside the
  vertices' projected bounding box, widened by a margin (one pixel, plus ``1e-5`` of ``f S / z_min``: ``S`` the
  coordinates' magnitude, for float32 arithmetic on the GPU), is covered by no triangle of the object.  An object
  with a vertex nearer than ``znear / 2`` (or behind the camera) is bounded by nothing: the whole canvas.
- **One small draw per object.**  `glphong.Renderer.silhouettes` draws each object by itself into an integer
  target, one sample per pixel at the pixel centre, with the same ``invariant gl_Position = u_view_projection *
  (u_model p)`` every program's vertex stage computes from the same uniforms, and the same back-face culling: the
  pixels the object's instance pass covers when it is rendered alone, without building a scene, a G-buffer and its
  planes for it.  A scene with a textured alpha mask (which that draw does not follow) renders each object alone.
- **No large canvas for an object inside the image.**  An object whose widened box lies within the image's
  pixel centres covers no pixel of the large canvas beyond the image: its truncated part is empty without
  being rendered.  Objects that may reach beyond the border are rendered on the large canvas, grouped as
  above.
- **An object whose box misses the canvas** covers none of it: an empty silhouette, not rendered.
- **An object apart from all others needs no render at all.**  Where an object's region in the image meets no
  other object's region, no other fragment competes inside it, so the frame's own instance pass (``visible``, drawn
  with the same ``invariant gl_Position = u_view_projection * (u_model p)`` as every program's vertex stage, the
  same culling and the same viewport) is its whole silhouette in the image; a mask with a pixel outside its region
  is rendered instead, as a check.

The files are the same, byte for byte, as from one render per object and canvas (``tests/datasets/
test_bop_batch.py`` compares them with that reference, objects inside and across the border, hidden and apart).
"""
import math

import numpy as np

from glphong.gpu.passes import opencv_rotation
from glphong.scene.camera import IntrinsicsCamera
from glphong.scene.scene import Scene

__all__ = ["silhouettes", "object_boxes", "gt_info"]

#: the margin [px] added on every side of an object's projected box, besides the float32 allowance
MARGIN_PX = 1.0
#: the relative error allowed to the GPU's float32 transform of a vertex, times ``f S / z_min`` [px]
FLOAT32_ALLOWANCE = 1e-5
_EMPTY = (np.zeros(0, np.int64), np.zeros(0, np.int64))


def object_boxes(scene, k):
    """The image region each object of ``scene`` may cover, from its mesh's vertices (module docstring).

    Parameters
    ----------
    scene : Scene
        Seen by a camera whose OpenCV intrinsic matrix is ``k``; every object's pose rigid.
    k : (3, 3) float64 ndarray
        ``cam_K`` of the rendered image size [px] (`glphong.datasets.bop.bop_camera_matrix`).

    Returns
    -------
    list of (4,) float64 ndarray or None
        Per object ``(u0, u1, v0, v1)`` [px, OpenCV's image coordinates: pixel centres at integers]: no pixel
        whose centre lies outside ``[u0, u1] x [v0, v1]`` is covered by the object; None where a vertex is nearer
        than ``znear / 2`` to the camera's plane, or behind it (nothing bounds it).
    """
    camera = scene.camera
    rotation = opencv_rotation(camera)
    centre = camera.pose[:3, 3]
    limit = 0.5 * camera.znear
    f = max(k[0, 0], k[1, 1])
    boxes = []
    for obj in scene.objects:
        positions = obj.mesh.positions
        turn = rotation @ obj.pose[:3, :3]
        points = positions @ turn.T + rotation @ (obj.pose[:3, 3] - centre)  # OpenCV's camera frame [m]
        z = points[:, 2]
        if not z.min() >= limit:
            boxes.append(None)
            continue
        u = k[0, 0] * points[:, 0] / z + k[0, 2]
        v = k[1, 1] * points[:, 1] / z + k[1, 2]
        size = np.abs(positions).max() + np.abs(obj.pose[:3, 3]).max() + np.abs(centre).max()
        margin = MARGIN_PX + FLOAT32_ALLOWANCE * f * size / z.min()
        boxes.append(np.array([u.min() - margin, u.max() + margin, v.min() - margin, v.max() + margin]))
    return boxes


def _pixels(box, width, height, offset=(0, 0)):
    """The pixels ``(x0, x1, y0, y1)`` (inclusive) of a ``width x height`` canvas whose centres lie in ``box``
    shifted by ``offset`` [px]; the whole canvas for None (unbounded), None where no centre lies in it."""
    if box is None:
        return 0, width - 1, 0, height - 1
    u0, u1, v0, v1 = box + np.repeat(np.asarray(offset, np.float64), 2)
    x0, x1 = max(0, math.ceil(max(u0, -1.0))), min(width - 1, math.floor(min(u1, width)))
    y0, y1 = max(0, math.ceil(max(v0, -1.0))), min(height - 1, math.floor(min(v1, height)))
    return (x0, x1, y0, y1) if x0 <= x1 and y0 <= y1 else None


def _within(box, width, height):
    """Whether every pixel centre of ``box`` (None: unbounded) lies within the ``width x height`` image."""
    if box is None:
        return False
    u0, u1, v0, v1 = box
    return bool(u0 > -1.0 and v0 > -1.0 and u1 < width and v1 < height)


def _meet(a, b):
    return a[0] <= b[1] and b[0] <= a[1] and a[2] <= b[3] and b[2] <= a[3]


def _subscene(scene, objects, camera):
    """A scene of ``scene``'s lights and ambient light seen by ``camera``, holding ``objects`` as they are."""
    out = Scene(camera, scene.lights, scene.ambient)
    for obj in objects:
        out.add(obj.mesh, obj.material, pose=obj.pose, name=obj.name, casts_shadow=obj.casts_shadow,
                instance_id=obj.instance_id, category=obj.category)
    return out


def _coverage(renderer, scene, camera, indices, pixels):
    """``{index: (H, W) bool}``: where each of ``scene.objects[indices]`` covers the renderer's canvas when
    rendered alone, seen by ``camera``: `glphong.Renderer.silhouettes` (each object drawn by itself, one small draw
    each), or, in a scene with a textured alpha mask (which that draw does not follow) or on a canvas beyond
    ``renderer.silhouette_limit``, the instance pass of each object rendered alone; ``pixels`` the region of each object (`_pixels`, None: nothing, not drawn)."""
    objects = scene.objects
    out = {i: np.zeros((renderer.height, renderer.width), bool) for i in indices if pixels[i] is None}
    drawn = [i for i in indices if pixels[i] is not None]
    if not drawn:
        return out
    seen = scene if camera is scene.camera else _subscene(scene, objects, camera)
    if max(renderer.width, renderer.height) > renderer.silhouette_limit or any(
            o.material.alpha_mask is not None and o.material.alpha_mask.textured for o in objects):
        for i in drawn:
            alone = _subscene(scene, [objects[i]], camera)
            out[i] = renderer.render(alone, passes=("instance",)).instance == objects[i].instance_id
        return out
    out.update(zip(drawn, renderer.silhouettes(seen, drawn)))
    return out


def _outside(mask, pixels):
    """Whether ``mask`` holds a pixel outside the region ``pixels``."""
    x0, x1, y0, y1 = pixels
    return int(np.count_nonzero(mask)) != int(np.count_nonzero(mask[y0:y1 + 1, x0:x1 + 1]))


def silhouettes(scene, renderer, k, count_truncated, large=None, visible=None):
    """Each object's whole silhouette, as rendered alone (module docstring).

    Parameters
    ----------
    scene : Scene
    renderer : Renderer
        At the image's size; resized to three times it and back where an object may reach beyond the border
        and ``count_truncated`` (unless ``large`` is given).
    k : (3, 3) float64 ndarray
        ``cam_K`` of the image (`glphong.datasets.bop.bop_camera_matrix`).
    count_truncated : bool
        Also the pixels beyond the image, on a canvas three times its size, the image at its centre.
    large : callable, optional
        Returns a renderer of the large canvas (three times the image's size, ``renderer``'s options) to use
        instead of resizing ``renderer``: called where an object needs it (a batch's worker keeps one).
    visible : (H, W) uint32 ndarray, optional
        The scene's instance pass as ``renderer`` drew it: the silhouette of an object apart from all others.

    Returns
    -------
    list of (inside, outside)
        Per object: ``inside`` (H, W) bool, the image's pixels its silhouette covers; ``outside`` ``(ys, xs)``
        int64 arrays [px, image coordinates, so beyond ``[0, H) x [0, W)``] of those beyond the image (empty
        without ``count_truncated``).
    """
    width, height = renderer.width, renderer.height
    if count_truncated and scene.objects and 3 * max(width, height) * renderer.supersample > 16384:
        raise ValueError(f"count_truncated=True renders each object on a canvas three times the image's size "
                         f"({3 * width}x{3 * height}), beyond the renderer's 16384 px (supersample "
                         f"{renderer.supersample}): pass count_truncated=False (px_count_all and bbox_obj then "
                         "count the image's pixels only)")
    indices = list(range(len(scene.objects)))
    boxes = object_boxes(scene, k)
    pixels = [_pixels(b, width, height) for b in boxes]
    inside = {}
    if visible is not None:  # objects apart from all others: the frame's own instance pass
        for i in indices:
            if pixels[i] is not None and not any(pixels[j] is not None and _meet(pixels[i], pixels[j])
                                                 for j in indices if j != i):
                mask = visible == scene.objects[i].instance_id
                if not _outside(mask, pixels[i]):
                    inside[i] = mask
    inside.update(_coverage(renderer, scene, scene.camera, [i for i in indices if i not in inside], pixels))
    outside = {i: _EMPTY for i in indices}
    if count_truncated and scene.objects:
        cut = [i for i in indices if not _within(boxes[i], width, height)]
        if cut:
            camera = scene.camera
            canvas = IntrinsicsCamera(k[0, 0], k[1, 1], k[0, 2] + width, k[1, 2] + height, 3 * width, 3 * height,
                                      pose=camera.pose, znear=camera.znear, zfar=camera.zfar)
            pixels = [_pixels(b, 3 * width, 3 * height, (width, height)) for b in boxes]
            if large is not None:
                big = _coverage(large(), scene, canvas, cut, pixels)
            else:
                renderer.resize(3 * width, 3 * height)
                try:
                    big = _coverage(renderer, scene, canvas, cut, pixels)
                finally:
                    renderer.resize(width, height)
            for i in cut:
                big[i][height:2 * height, width:2 * width] = False  # the image's own pixels: the exact render's
                ys, xs = np.nonzero(big[i])
                outside[i] = (ys - height, xs - width)
    return [(inside[i], outside[i]) for i in indices]


def _extent(mask, axis, beyond=()):
    """The smallest and largest row (``axis`` 1) or column (``axis`` 0) index of ``mask``'s pixels and of the
    indices ``beyond`` (int array, pixels outside the image)."""
    where = np.flatnonzero(mask.any(axis=axis))
    ends = [int(where[0]), int(where[-1])] if where.size else []
    if len(beyond):
        ends += [int(beyond.min()), int(beyond.max())]
    return min(ends), max(ends)


def _bbox(rows, columns):
    """bop_toolkit ``misc.calc_2d_bbox(xs, ys)`` (clip=False) of pixels spanning ``rows`` and ``columns`` (each
    ``(min, max)``): ``[x_min, y_min, x_max - x_min, y_max - y_min]``."""
    return [columns[0], rows[0], columns[1] - columns[0], rows[1] - rows[0]]


def gt_info(inside, outside, visible, depth_units):
    """One object's ``scene_gt_info`` entry (bop_toolkit ``scripts/calc_gt_info.py``).

    Parameters
    ----------
    inside : (H, W) bool ndarray
        Its whole silhouette's pixels in the image.
    outside : tuple of two int ndarrays
        ``(ys, xs)`` of its silhouette's pixels beyond the image [px, image coordinates].
    visible : (H, W) bool ndarray
        Its visible pixels (the instance pass of the scene).
    depth_units : (H, W) uint16 ndarray
        The depth image's values (0 where nothing is seen).

    Returns
    -------
    dict
        ``bbox_obj``, ``bbox_visib`` ([x, y, width, height] px; ``[-1, -1, -1, -1]`` where nothing is visible),
        ``px_count_all``, ``px_count_valid``, ``px_count_visib`` (int) and ``visib_fract`` (float).
    """
    px_count_all = int(np.count_nonzero(inside)) + int(outside[0].size)
    px_count_valid = int(np.count_nonzero(depth_units[inside]))
    px_count_visib = int(np.count_nonzero(visible))
    bbox_obj = bbox_visib = [-1, -1, -1, -1]
    if px_count_visib > 0:  # the toolkit gives both boxes only where something is visible
        bbox_obj = _bbox(_extent(inside, 1, outside[0]), _extent(inside, 0, outside[1]))
        bbox_visib = _bbox(_extent(visible, 1), _extent(visible, 0))
    return {"bbox_obj": bbox_obj, "bbox_visib": bbox_visib, "px_count_all": px_count_all,
            "px_count_valid": px_count_valid, "px_count_visib": px_count_visib,
            "visib_fract": px_count_visib / float(px_count_all) if px_count_all > 0 else 0.0}
