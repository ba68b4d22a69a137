"""The frame passes: what a render gives besides the radiance, from one G-buffer draw (docs/design.md section 15).

Each pass is a per-pixel array at the output size, row 0 at the top, sampled at the pixel centre (the G-buffer is
drawn with one sample per pixel whatever the renderer's ``samples`` and ``supersample``), 0 where no object covers
the centre:

- ``depth`` (H, W) float32 [m]: the point's distance from the camera along its viewing axis, ``(p - e) . f``.
- ``distance`` (H, W) float32 [m]: its range along the pixel's ray, ``|p - e|`` (an orthographic camera's rays start
  on its plane: the depth).
- ``normal`` (H, W, 3) float32: the world-space unit shading normal as shaded (the two-sided flip and a normal map
  included); ``normal_camera``: the same in OpenCV's camera frame (x right, y down, z forward), ``R_cv n`` with
  ``R_cv = diag(1, -1, -1) R^T``.
- ``uv`` (H, W, 2) float32: the interpolated texture coordinates (every object needs uvs).
- ``instance``, ``category`` (H, W) uint32: the covering object's `SceneObject.instance_id` and ``category``; 0 the
  background.
- ``object_coordinates`` (H, W, 3) float32 [m]: the point in its object's own frame (the pose undone, interpolated
  from the vertices' object-frame positions); ``nocs``: that point in the unit cube of the mesh's axis-aligned box,
  ``(o - lo) / (hi - lo)`` per axis (0.5 on an axis where the box is flat), clamped to [0, 1] (the float32
  interpolation puts a point on the box's face up to an ulp outside it).
- ``flow``, ``backward_flow`` (H, W, 2) float32 [px], x right, y down: where the point, moving with its own object,
  lands in ``next_scene`` (the same objects in the same order at their next poses, seen by its camera) minus the
  pixel centre; from ``previous_scene`` for the backward one.  Kubric's convention: a pure projection, occlusion in
  the other frame ignored; NaN where the point is not in front of the other camera (its ``w <= 0``).
- ``matte``: ``matte_ids`` (H, W, k) uint32 and ``matte_fractions`` (H, W, k) float32, each pixel's ``k`` objects
  of largest share of its square, from a draw of its own at ``s x s`` samples a pixel (`glphong.gpu.matte`).
"""
import numpy as np

from glphong.gpu.matte import matte_objects
from glphong.scene.scene import Scene

__all__ = ["PASSES", "GEOMETRY_PASSES", "requested_passes", "gbuffer_planes", "check_passes", "check_corresponds",
           "derive_passes",
           "opencv_rotation"]

#: every pass `glphong.Renderer.render` gives, in the order a `Frame` lists them
PASSES = ("radiance", "depth", "distance", "normal", "normal_camera", "uv", "instance", "category",
          "object_coordinates", "nocs", "flow", "backward_flow", "matte")
#: the passes made from the G-buffer draw (the radiance draw's planes where it is asked for)
GEOMETRY_PASSES = PASSES[1:-1]
_FROM_OBJECT = ("object_coordinates", "nocs", "flow", "backward_flow")


def requested_passes(passes, depth=False, normals=False):
    """The passes of a call, checked and in `PASSES` order: ``passes`` (default ``('radiance',)``) plus 'depth' and
    'normal' where the older flags ask for them.

    Raises
    ------
    TypeError
        ``passes`` not a sequence of str.
    ValueError
        An unknown name (the known ones listed).
    """
    if passes is None:
        names = ["radiance"]
    elif isinstance(passes, str):
        names = [passes]
    else:
        try:
            names = list(passes)
        except TypeError:
            raise TypeError(f"passes must be a sequence of pass names (got {type(passes).__name__})") from None
    for name in names:
        if not isinstance(name, str):
            raise TypeError(f"passes must be a sequence of pass names, str (got {name!r})")
        if name not in PASSES:
            raise ValueError(f"unknown pass {name!r}; the passes are {', '.join(PASSES)}")
    chosen = set(names) | ({"depth"} if depth else set()) | ({"normal"} if normals else set())
    return tuple(name for name in PASSES if name in chosen)


def gbuffer_planes(names):
    """The G-buffer planes (beyond position and normal) the passes ``names`` read (frozenset of str)."""
    return frozenset(("uv",) if "uv" in names else ()) | frozenset(
        ("object",) if any(n in _FROM_OBJECT for n in names) else ())


def check_passes(scene, names, next_scene=None, previous_scene=None):
    """Whether ``scene`` can have the passes ``names``; raises ValueError naming the pass and the fix."""
    if "matte" in names:
        matte_objects(scene)
    if "uv" in names:
        for obj in scene.objects:
            if obj.mesh.uvs is None:
                raise ValueError(f"the 'uv' pass needs texture coordinates on every object, and object {obj.name!r} "
                                 "has none: give its MeshData uvs=, load a mesh with uvs, or leave 'uv' out")
    for name, other, argument in (("flow", next_scene, "next_scene"), ("backward_flow", previous_scene,
                                                                        "previous_scene")):
        if name in names:
            check_corresponds(scene, other, name, argument)
        elif other is not None:
            raise ValueError(f"{argument} is given but the {name!r} pass is not asked for: add it to passes")


def check_corresponds(scene, other, name, argument):
    """Whether ``other`` (the ``argument`` of pass ``name``, 'next_scene' or 'previous_scene') is ``scene`` at another
    time: a Scene holding the same MeshData objects in the same order; raises ValueError (TypeError) naming the fix."""
    if other is None:
        raise ValueError(f"the {name!r} pass needs {argument}: the same objects, in the same order, at their "
                         "poses in that frame, seen by its camera")
    if not isinstance(other, Scene):
        raise TypeError(f"{argument} must be a glphong.Scene (got {type(other).__name__})")
    if len(other.objects) != len(scene.objects):
        raise ValueError(f"the {name!r} pass needs {argument} to hold the same objects in the same order: it has "
                         f"{len(other.objects)} objects, the scene {len(scene.objects)}")
    for i, (a, b) in enumerate(zip(scene.objects, other.objects)):
        if a.mesh is not b.mesh:
            raise ValueError(f"the {name!r} pass needs {argument} to hold the same objects in the same order: its "
                             f"object {i} ({b.name!r}) has another mesh than the scene's ({a.name!r}); add the same "
                             "MeshData (scene.objects[i].mesh) at the other pose")


def opencv_rotation(camera):
    """World-to-camera rotation of OpenCV's frame (x right, y down, z forward), (3, 3) float64:
    ``diag(1, -1, -1) R^T`` with ``R`` the camera pose's rotation."""
    return np.diag([1.0, -1.0, -1.0]) @ camera.pose[:3, :3].T


def _gatherer(shape, rows, columns):
    """``gather(plane)``: a G-buffer plane's values at the covered pixels ``rows``, ``columns`` ((N, C) or (N,)).

    A plane that is a row-flipped view of a C-ordered read-back (channels from 0, as `GBuffer.from_planes` with
    ``copy=False`` gives) is gathered with ``numpy.take`` from that read-back by flat index, ten times faster than
    fancy indexing on the strided view; anything else by fancy indexing."""
    height, width = shape
    flipped_flat = (height - 1 - rows) * width + columns

    def gather(plane):
        base = plane.base
        if base is not None and base.ndim == 3 and base.flags.c_contiguous and base.shape[:2] == shape \
                and plane.ndim == 3 and plane.dtype == base.dtype and plane.strides[0] == -base.strides[0] \
                and plane.strides[1:] == base.strides[1:] \
                and plane.__array_interface__["data"][0] == base.__array_interface__["data"][0] + (height - 1) * \
                base.strides[0]:
            return np.take(base.reshape(-1, base.shape[2]), flipped_flat, axis=0)[:, :plane.shape[2]]
        return plane[rows, columns]

    return gather


def derive_passes(scene, gbuffer, names, next_scene=None, previous_scene=None):
    """The geometry passes ``names`` of a G-buffer (`glphong.gpu.frame.GBuffer` with the planes `gbuffer_planes`
    asks for, C-ordered or strided views of the read-back planes): a dict of name to array (module docstring),
    computed on the covered pixels only."""
    mask = gbuffer.mask
    rows, columns = np.nonzero(mask)  # the covered pixels, row-major: gathers and scatters by index, not by mask
    flat = rows * mask.shape[1] + columns
    whole = flat.size == mask.size  # every pixel covered: no scatter
    index = gbuffer.object_index.reshape(-1)[flat]
    camera = scene.camera
    covered = _gatherer(mask.shape, rows, columns)
    out = {}

    def image(values, dtype=np.float32):  # the covered pixels' values in an image, 0 elsewhere
        if whole:
            return values.astype(dtype).reshape(mask.shape + values.shape[1:])
        full = np.zeros((mask.size,) + values.shape[1:], dtype)
        full[flat] = values
        return full.reshape(mask.shape + values.shape[1:])

    if "depth" in names or "distance" in names:
        offset = covered(gbuffer.position).astype(np.float64) - camera.position
        depth = offset @ -camera.pose[:3, 2]
        out["depth"] = image(depth)
        if "distance" in names:
            out["distance"] = image(np.sqrt(np.einsum("ij,ij->i", offset, offset)) if camera.eye[3] == 1.0 else depth)
    if "normal" in names:
        out["normal"] = np.ascontiguousarray(gbuffer.normal)
    if "normal_camera" in names:
        out["normal_camera"] = image(covered(gbuffer.normal).astype(np.float64) @ opencv_rotation(camera).T)
    if "uv" in names:
        out["uv"] = image(covered(gbuffer.uv))
    for name in ("instance", "category"):
        if name in names:
            table = np.array([getattr(o, "instance_id" if name == "instance" else "category") for o in scene.objects],
                             np.uint32)
            out[name] = image(table[index], np.uint32)
    if any(n in names for n in _FROM_OBJECT):
        obj = covered(gbuffer.object_coordinates)
        if "object_coordinates" in names:
            out["object_coordinates"] = image(obj)
        if "nocs" in names or "flow" in names or "backward_flow" in names:
            obj = obj.astype(np.float64)
        if "nocs" in names:
            out["nocs"] = image(_nocs(scene, obj, index))
        for name, other in (("flow", next_scene), ("backward_flow", previous_scene)):
            if name in names:
                out[name] = image(_flow(obj, index, (rows, columns), other, mask.shape))
    return out


def _per_object(table, index):
    """``table[index]`` column by column, (N, C) float64 for a per-object ``table`` (objects, C): one gather of a
    short table per column instead of a gather of whole rows."""
    return [np.take(table[:, c], index) for c in range(table.shape[1])]


def _nocs(scene, obj, index):
    """``(o - lo) / (hi - lo)`` per axis with each object's box (0.5 on a flat axis), clamped to [0, 1], (N, 3)
    float64 for points ``obj`` (N, 3) float64 of objects ``index`` (N,)."""
    lo = np.array([o.mesh.box[0] for o in scene.objects], np.float64).reshape(-1, 3)  # `MeshData.box`: kept
    hi = np.array([o.mesh.box[1] for o in scene.objects], np.float64).reshape(-1, 3)
    out = np.empty(obj.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        for axis, (low, span) in enumerate(zip(_per_object(lo, index), _per_object(hi - lo, index))):
            out[:, axis] = np.where(span > 0, (obj[:, axis] - low) / span, 0.5)
    return np.clip(out, 0.0, 1.0, out=out)


def _flow(obj, index, pixels, other, shape):
    """Where each point ``obj`` (N, 3) float64 of objects ``index`` (N,) at ``pixels`` (rows (N,), columns (N,))
    lands in ``other`` minus its pixel centre [px], (N, 2) float64: moved by its object's pose there and projected by
    that scene's camera (its projection and view matrices, clip to window coordinates); NaN where ``w <= 0`` (not in
    front of the camera)."""
    height, width = shape
    camera = other.camera
    clip_from_world = camera.projection_matrix(width / height) @ camera.view_matrix()
    poses = np.array([clip_from_world @ o.pose for o in other.objects]).reshape(-1, 4, 4)

    def row(k):  # clip coordinate k of every point: sum_j M[k, j] o_j + M[k, 3], with its object's M
        m = _per_object(poses[:, k, :], index)
        return m[0] * obj[:, 0] + m[1] * obj[:, 1] + m[2] * obj[:, 2] + m[3]

    x, y, w = row(0), row(1), row(3)
    out = np.empty((obj.shape[0], 2))
    with np.errstate(divide="ignore", invalid="ignore"):
        out[:, 0] = (x / w + 1.0) * (0.5 * width) - (pixels[1] + 0.5)
        out[:, 1] = (1.0 - y / w) * (0.5 * height) - (pixels[0] + 0.5)
    out[w <= 0] = np.nan
    return out
