"""The float64 twin of the frame passes, and the band each GPU pass must lie in (docs/design.md section 15; the image
conventions of section 2, the band's eps of section 4).

Every pass is computed by an independent ray cast against every object's triangles: no GPU code, projection
matrix or shader is used, only the camera's rays (`Camera.sample_rays`) and its image plane
(`Camera._image_plane`).  ``verify(..., passes=...)`` compares the GPU's passes with them pixel by pixel.

Conventions
-----------
- Samples: each pixel (row j, column i; row 0 at the top) is sampled at the offsets `SAMPLE_OFFSETS` [px] from its
  top-left corner (x right, y down): its centre ``(0.5, 0.5)`` and the four points ``(0.5 +- SUBPIXEL, 0.5 +-
  SUBPIXEL)``, since the rasteriser may place its sample up to `SUBPIXEL` from the centre (its subpixel snap).  The
  image position of a sample is ``(xp, yp) = (i + ox, j + oy)``.
- Rays: `Camera.sample_rays`: unit directions ``d``, from the camera centre (perspective) or from the sample's point
  on the camera plane (orthographic).  Hits: Moller-Trumbore in float64 against the world triangles ``pose @
  positions`` (positions cast to float64), both faces (no culling), edges inclusive; a hit counts where ``t >
  T_MIN`` and its depth along the viewing axis ``(p - c) . f``, ``f = -camera.pose[:3, 2]``, lies in ``[znear,
  zfar]`` (`glphong.checks.raycast`).  The nearest ``t`` wins.  Objects whose material has a constant alpha mask
  below its cutoff are not drawn (`glphong.definitions.surface.alpha_masked`) and are skipped; a textured alpha mask
  is refused.  Blended objects (`glphong.AlphaBlend`) are skipped: the passes are the nearest opaque surface's
  (`glphong.checks.blend_twin` casts their layers).
- Candidates: each triangle is tested only against the pixels of its screen box, the box of its vertices projected
  by a pinhole model built from ``_image_plane`` (affine in ``(xp, yp)``: evaluated at three points and inverted),
  widened by one pixel; a triangle with a vertex not in front of a perspective camera (``c_z >= 0``) gets the whole
  image, one with every vertex nearer than ``znear`` or farther than ``zfar`` none.
- Front: the object's counter-clockwise side faces the ray's origin: Moller-Trumbore's ``det > 0``, reversed for a
  mirroring pose (``det(pose[:3, :3]) < 0``), as the renderer sets ``glFrontFace``.
- Depth-buffer ties: the GPU keeps the window depth ``d = (f / (f - n)) (1 - n / z)`` (perspective; linear in ``z``
  for orthographic) in a 24-bit buffer with float32 arithmetic, so two surfaces at view depths ``z1 < z2`` may be
  drawn either way round when ``z2 - z1 <= 8 eps (f - n) z1^2 / (f n)`` (perspective) or ``8 eps (f - n)``
  (orthographic), ``eps = 2^-24``: the next hit behind the nearest one is then kept as the sample's *tie*.  A
  hit of the same object at the same point, ``t2 - t1 <= SAME_POINT t1`` (the neighbouring triangle at a shared
  edge or vertex), is that surface again, not a tie (the samples on either side of the edge show both triangles);
  so are two coincident faces of one mesh.  One tie is kept per sample.

Passes (float64; ``p`` the world point, ``c`` the camera's position, ``oc`` the object point; 0 where no hit)
------------------------------------------------------------------------------------------------------------
- ``depth`` ``(p - c) . f`` [m]; ``distance`` ``t``, the range from the ray's origin [m];
- ``normal`` ``normalize(N (sum_k b_k n_k))`` with ``N = inv(pose[:3, :3]).T`` and ``n_k`` the float32 vertex
  normals, negated where the material is two-sided and the hit is not ``front``; 0 where zero or not finite; NaN
  (unchecked) where the material has a normal map; ``normal_camera`` ``diag(1, -1, -1) R^T normal`` (OpenCV's
  camera frame: x right, y down, z forward);
- ``uv`` ``sum_k b_k uv_k``; ``object_coordinates`` ``oc = sum_k b_k x_k`` [m] of the float32 object positions;
  ``nocs`` ``(oc - lo) / (hi - lo)`` per axis, ``lo``, ``hi`` the mesh's bounds, clamped to [0, 1] (0.5 on a flat
  axis);
- ``instance``, ``category`` the object's ``instance_id`` (default its index + 1) and ``category`` (default 0),
  int64;
- ``flow`` the image position [px] of ``pose' oc`` seen by the next scene's camera (``pose'`` the same object's
  pose there; its camera-frame point ``q = R'^T (p' - t')``, plane coordinates ``(q_x, q_y) / -q_z`` or ``(q_x,
  q_y)``, then the inverse of ``_image_plane``) minus the pixel's centre ``(i + 0.5, j + 0.5)``, as the GPU's pass
  (Kubric's convention; the spread over the samples then holds the GPU's snapped sample); NaN where ``pose' oc`` is
  not in front of a perspective camera (``q_z >= 0``); ``backward_flow`` the same with the previous scene.

Band (`pass_bands`): the min and max over the samples (and over the ties), widened on both sides by the float32
rounding: depth and distance ``32 eps (s + |c|)`` (``|c|`` Euclidean), ``s`` the largest ``|world vertex
coordinate|`` of the hit object; object_coordinates ``8 eps m``, ``m`` its largest ``|object vertex coordinate|``;
nocs that over ``hi - lo`` (0 on a flat axis); uv ``8 eps max|uv|``; normal and normal_camera ``16 eps``; flow: its
min and max at ``oc`` and ``oc +- r e_k``, ``r = 8 eps m``.  NaN values give NaN (unchecked) bounds.  ``instance``
and ``category`` get the set of ids the samples and ties show.
"""
from dataclasses import dataclass, replace

import numpy as np

from glphong.core import validate as _validate
from glphong.gpu.matte import drawn_objects
from glphong.gpu.passes import check_corresponds
from glphong.gpu.transmission import one_sided_transmissive
from glphong.twin.band import EPS
from glphong.twin.functions import dot, safe_normalize
from glphong.checks.raycast import T_MIN

__all__ = ["SUBPIXEL", "SAMPLE_OFFSETS", "PASS_NAMES", "CHUNK_PAIRS", "PixelHits", "cast_pixels", "twin_passes",
           "pass_bands", "depth_tie"]

#: [px] how far the rasteriser may place a sample from the pixel centre (its subpixel snap)
SUBPIXEL = 2.0 ** -8
#: (5, 2) float64 sub-pixel sample positions [px from the pixel's top-left corner]: the centre, then its neighbours
SAMPLE_OFFSETS = 0.5 + SUBPIXEL * np.array([[0.0, 0.0], [-1.0, -1.0], [1.0, -1.0], [-1.0, 1.0], [1.0, 1.0]])
SAMPLE_OFFSETS.setflags(write=False)
#: the passes this module twins
PASS_NAMES = ("depth", "distance", "normal", "normal_camera", "uv", "instance", "category", "object_coordinates",
              "nocs", "flow", "backward_flow")
#: ray-triangle pairs tested at once (about 60 MB of float64 temporaries)
CHUNK_PAIRS = 1 << 19
#: the depth buffer's resolution in units of eps (see the module)
TIE_ULPS = 8.0
#: hits of one object whose ray parameters differ by at most this relative amount are one point (a shared edge)
SAME_POINT = 2.0 ** -30
_ID_PASSES = ("instance", "category")
_OTHER_SCENE = {"flow": "next_scene", "backward_flow": "previous_scene"}
#: OpenGL camera frame to OpenCV's (x right, y down, z forward)
_GL_TO_CV = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class PixelHits:
    """The nearest hit of every sample ray, and the next one where the depth buffer cannot tell them apart.

    Attributes
    ----------
    offsets : (S, 2) float64 ndarray
        The sample positions [px from the pixel's top-left corner, x right, y down].
    object_index : (S, H, W) int64 ndarray
        Index into ``scene.objects`` of the hit object, -1 where the ray hits nothing.
    triangle : (S, H, W) int64 ndarray
        The hit triangle, a row of the object's ``mesh.indices``; -1 where none.
    barycentric : (S, H, W, 3) float64 ndarray
        Weights of the triangle's vertices 0, 1 and 2 (sum 1); 0 where none.
    t : (S, H, W) float64 ndarray
        Ray parameter along the unit direction from the ray's origin [m]; 0 where none.
    position : (S, H, W, 3) float64 ndarray
        The world point ``o + t d`` [m]; 0 where none.
    front : (S, H, W) bool ndarray
        The object's counter-clockwise side faces the ray's origin (a mirroring pose reverses it).
    tie_object_index, tie_triangle, tie_barycentric, tie_t, tie_position, tie_front
        The same for the next hit behind the nearest (not the same surface point again) where the depth buffer
        cannot tell them apart (`depth_tie`); ``tie_object_index`` is -1 where there is no tie.  `ties` gives them
        as a `PixelHits` of their own.
    """

    offsets: np.ndarray
    object_index: np.ndarray
    triangle: np.ndarray
    barycentric: np.ndarray
    t: np.ndarray
    position: np.ndarray
    front: np.ndarray
    tie_object_index: np.ndarray
    tie_triangle: np.ndarray
    tie_barycentric: np.ndarray
    tie_t: np.ndarray
    tie_position: np.ndarray
    tie_front: np.ndarray

    def ties(self):
        """The tie hits as the nearest ones of a `PixelHits` (whose own ties are empty)."""
        return replace(self, object_index=self.tie_object_index, triangle=self.tie_triangle,
                       barycentric=self.tie_barycentric, t=self.tie_t, position=self.tie_position, front=self.tie_front,
                       tie_object_index=np.full_like(self.tie_object_index, -1))


# --------------------------------------------------------------------------- the camera, by its image plane
def _parallel(camera):
    """Whether the camera's views are parallel (orthographic): its homogeneous eye has ``w = 0``."""
    return camera.eye[3] == 0.0


def _image_map(camera, width, height):
    """``(A, b)`` with ``(x, y) = A (xp, yp) + b`` the camera's affine ``_image_plane`` for this image size."""
    x, y = camera._image_plane(np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), width, height)
    b = np.array([x[0], y[0]])
    return np.array([[x[1] - x[0], x[2] - x[0]], [y[1] - y[0], y[2] - y[0]]]), b


def _project(camera, width, height, points):
    """``(xp, yp, ahead)``, each (...): the image positions [px from the image's top-left corner, x right, y down]
    of world points (..., 3) [m] by the camera's own image plane (no projection matrix), NaN where not ``ahead``, in
    front of the camera plane (``c_z < 0``; always for an orthographic camera)."""
    r, t = camera.pose[:3, :3], camera.pose[:3, 3]
    c = (np.asarray(points, dtype=np.float64) - t) @ r  # R^T (p - t), row-wise
    if _parallel(camera):
        ahead = np.ones(c.shape[:-1], bool)
        x, y = c[..., 0], c[..., 1]
    else:
        ahead = c[..., 2] < 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(ahead, -1.0 / c[..., 2], np.nan)
        x, y = c[..., 0] * w, c[..., 1] * w
    a, b = _image_map(camera, width, height)
    inv = np.linalg.inv(a)
    x, y = x - b[0], y - b[1]
    return inv[0, 0] * x + inv[0, 1] * y, inv[1, 0] * x + inv[1, 1] * y, ahead


def depth_tie(camera, z1, z2):
    """Whether the depth buffer may order two surfaces at view depths ``z1 <= z2`` [m] (arrays (...)) either way:
    ``z2 - z1 <= 8 eps (f - n) z1^2 / (f n)`` (perspective) or ``<= 8 eps (f - n)`` (orthographic); (...) bool."""
    n, f = camera.znear, camera.zfar
    z1, z2 = np.asarray(z1, dtype=np.float64), np.asarray(z2, dtype=np.float64)
    scale = np.ones_like(z1) if _parallel(camera) else z1 * z1 / (f * n)
    return z2 - z1 <= TIE_ULPS * EPS * (f - n) * scale


# --------------------------------------------------------------------------- the ray cast
def _drawn_objects(scene):
    """Indices of the objects the renderer draws; ValueError for a textured alpha mask, which is not twinned."""
    return drawn_objects(scene, lambda obj: f"object {obj.name!r} has a textured alpha mask: verify of passes does not "
                                            "check textured alpha masks yet")


def _world_triangles(scene, drawn):
    """``(corners, owner, local)``: every drawn triangle's world corners (F, 3, 3) float64 [m], its object's index
    (F,) and its row in that object's mesh (F,)."""
    corners, owner, local = [np.zeros((0, 3, 3))], [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for index in drawn:
        obj = scene.objects[index]
        world = obj.mesh.positions.astype(np.float64) @ obj.pose[:3, :3].T + obj.pose[:3, 3]
        corners.append(world[obj.mesh.indices.astype(np.int64)])
        owner.append(np.full(obj.mesh.triangle_count, index, np.int64))
        local.append(np.arange(obj.mesh.triangle_count, dtype=np.int64))
    return np.concatenate(corners), np.concatenate(owner), np.concatenate(local)


def culled_back_faces(scene, owner, det):
    """Whether each hit is a back face the GPU culls, (M,) bool: a one-sided transmissive object's
    (`glphong.gpu.transmission.one_sided_transmissive`: its transmission pass and its G-buffer cull them, as a
    blended one's).  ``owner`` (M,) the hits' object indices, ``det`` (M,) their Moller-Trumbore determinants (> 0:
    the counter-clockwise side, reversed by a mirroring pose)."""
    objects = scene.objects
    cull = np.array([one_sided_transmissive(obj.material) for obj in objects] + [False])
    mirrored = np.array([obj.mirrored for obj in objects] + [False])
    return cull[owner] & ((det > 0.0) == mirrored[owner])


def _pixel_boxes(camera, width, height, corners):
    """Inclusive pixel ranges ``(i0, i1, j0, j1)``, each (F,) int64, that may hold a triangle's samples (see the
    module); ``i1 < i0`` or ``j1 < j0`` where none."""
    xp, yp, ahead = _project(camera, width, height, corners)
    whole = ~np.all(ahead, axis=1)
    depth = dot(corners - camera.pose[:3, 3], -camera.pose[:3, 2])
    unseen = np.all(depth < camera.znear, axis=1) | np.all(depth > camera.zfar, axis=1)
    span = []
    for v, size in ((xp, width), (yp, height)):
        lo = np.floor(np.where(whole, -2.0, np.clip(np.min(v, axis=1), -2.0, size + 1.0))).astype(np.int64)
        hi = np.floor(np.where(whole, size + 1.0, np.clip(np.max(v, axis=1), -2.0, size + 1.0))).astype(np.int64)
        span += [np.maximum(lo - 1, 0), np.minimum(hi + 1, size - 1)]
    i0, i1, j0, j1 = span
    return i0, np.where(unseen, -1, i1), j0, j1


def _moller_trumbore(o, d, v0, e1, e2):
    """``(t, u, v, det)`` of rays ``o + t d`` against triangles ``v0 + u e1 + v e2`` (arrays (..., 3) that broadcast),
    each (...) float64; ``det = e1 . (d x e2)`` is 0 for a ray in the triangle's plane (``t``, ``u``, ``v`` are then
    not finite).  With a shared origin ``s`` and ``q`` are formed once per triangle."""
    p = np.cross(d, e2)
    det = dot(e1, p)
    s = o - v0
    q = np.cross(s, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        return dot(e2, q) * inv, dot(s, p) * inv, dot(d, q) * inv, det


def _pairs(starts, ends, counts_x, i0, j0, a, b, width):
    """Triangle and pixel of the candidate pairs ``a .. b - 1`` of the enumeration (triangle-major, then row-major
    over its box): ``(triangle, pixel)``, each (b - a,) int64, ``pixel = j width + i``."""
    fa, fb = np.searchsorted(ends, [a, b - 1], side="right")
    idx = np.arange(fa, fb + 1)
    tri = np.repeat(idx, np.minimum(ends[idx], b) - np.maximum(starts[idx], a))
    local = np.arange(a, b) - starts[tri]
    nx = counts_x[tri]
    return tri, (j0[tri] + local // nx) * width + i0[tri] + local % nx


def _hits(camera, width, height, offsets, corners):
    """Every valid hit of every sample ray: ``(ray, t, triangle, u, v, det, depth)``, each (M,), with ``ray = (s H + j)
    W + i`` and ``triangle`` a row of ``corners``; and the rays ``(o, d)``: (3,) or (S H W, 3), and (S H W, 3)."""
    origins, directions = camera.sample_rays(width, height, offsets)
    pixels, samples = width * height, len(offsets)
    per_ray = origins.ndim > 1
    d = np.moveaxis(directions, 2, 0).reshape(samples, pixels, 3)
    o = np.moveaxis(origins, 2, 0).reshape(samples, pixels, 3) if per_ray else origins
    v0, e1, e2 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    i0, i1, j0, j1 = _pixel_boxes(camera, width, height, corners)
    nx, ny = np.maximum(i1 - i0 + 1, 0), np.maximum(j1 - j0 + 1, 0)
    ends = np.cumsum(nx * ny)
    starts = ends - nx * ny
    eye, forward = camera.pose[:3, 3], -camera.pose[:3, 2]
    found = []
    step = max(1, CHUNK_PAIRS // samples)
    total = int(ends[-1]) if len(ends) else 0
    for first in range(0, total, step):
        tri, pixel = _pairs(starts, ends, nx, i0, j0, first, min(first + step, total), width)
        ray_o = o[:, pixel] if per_ray else o
        t, u, v, det = _moller_trumbore(ray_o, d[:, pixel], v0[tri], e1[tri], e2[tri])  # (S, N): samples broadcast
        with np.errstate(invalid="ignore"):  # a ray in a triangle's plane: u + v is inf - inf, and not a hit
            ok = (det != 0.0) & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > T_MIN)
        sample, pair = np.nonzero(ok)
        t = t[ok]
        depth = dot((ray_o[ok] if per_ray else o) + t[:, None] * d[sample, pixel[pair]] - eye, forward)
        keep = (depth >= camera.znear) & (depth <= camera.zfar)
        columns = (sample * pixels + pixel[pair], t, tri[pair], u[ok], v[ok], det[ok], depth)
        found.append([column[keep] for column in columns])
    empty = [np.zeros(0, dt) for dt in (np.int64, float, np.int64, float, float, float, float)]
    return [np.concatenate(column) for column in zip(empty, *found)], (o.reshape(-1, 3) if per_ray else o,
                                                                          d.reshape(-1, 3))


def _fill(shape, o, d, ray, t, u, v, det, tri, owner, local, mirrored):
    """The hit arrays of `PixelHits` (object_index, triangle, barycentric, t, position, front), of ``shape`` (S, H, W),
    from one hit per listed ray."""
    size = int(np.prod(shape))
    object_index, triangle = np.full(size, -1, np.int64), np.full(size, -1, np.int64)
    bary, tt, position, front = np.zeros((size, 3)), np.zeros(size), np.zeros((size, 3)), np.zeros(size, bool)
    object_index[ray], triangle[ray] = owner[tri], local[tri]
    bary[ray] = np.stack([1.0 - u - v, u, v], axis=-1)
    tt[ray] = t
    position[ray] = (o[ray] if o.ndim > 1 else o) + t[:, None] * d[ray]
    front[ray] = (det > 0.0) != mirrored[owner[tri]]
    return (object_index.reshape(shape), triangle.reshape(shape), bary.reshape(shape + (3,)), tt.reshape(shape),
            position.reshape(shape + (3,)), front.reshape(shape))


def _nearest_and_tie(camera, ray, t, owner, depth):
    """``(first, tie)``: indices of each ray's nearest hit and of the hits that tie with their ray's nearest (see the
    module), in hits (M,) sorted by ray, then t."""
    if not len(ray):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    start = np.r_[True, ray[1:] != ray[:-1]]
    lead = np.maximum.accumulate(np.where(start, np.arange(len(ray)), 0))  # each hit's ray's nearest
    other = np.flatnonzero((owner != owner[lead]) | (t - t[lead] > SAME_POINT * t[lead]))
    other = other[np.r_[True, ray[other][1:] != ray[other][:-1]]] if len(other) else other
    return np.flatnonzero(start), other[depth_tie(camera, depth[lead[other]], depth[other])]


def cast_pixels(scene, width, height, offsets=SAMPLE_OFFSETS):
    """Ray cast every sample of every pixel against every drawn object's triangles, in float64.

    Parameters
    ----------
    scene : glphong.Scene
    width, height : int
        Image size [px].
    offsets : (S, 2) array_like
        Sample positions [px from the pixel's top-left corner, x right, y down] (default `SAMPLE_OFFSETS`).

    Returns
    -------
    PixelHits
        Arrays of shape (S, H, W) (and a last axis of 3 for barycentric and position).

    Raises
    ------
    ValueError
        An object's material has a textured alpha mask (not twinned).

    Notes
    -----
    Measured on 2 cores at 256x256 px and the 5 samples: an icosphere(4) and a 2-triangle floor 0.25-0.30 s;
    102,400 triangles (icospheres 6 and 5) 0.70 s.
    """
    width, height = _validate.positive_int("width", width, 1, 16384), _validate.positive_int("height", height, 1, 16384)
    offsets = _validate.real_array("offsets", offsets, "an (S, 2) array of real numbers")
    if offsets.ndim != 2 or offsets.shape[1] != 2 or not len(offsets) or not np.all(np.isfinite(offsets)):
        raise ValueError(f"offsets must be a finite (S, 2) array with S >= 1 (got shape {offsets.shape})")
    camera = scene.camera
    corners, owner, local = _world_triangles(scene, _drawn_objects(scene))
    (ray, t, tri, u, v, det, depth), (o, d) = _hits(camera, width, height, offsets, corners)
    drawn = ~culled_back_faces(scene, owner[tri], det)
    order = np.lexsort((t[drawn], ray[drawn]))
    ray, t, tri, u, v, det, depth = (a[drawn][order] for a in (ray, t, tri, u, v, det, depth))
    first, second = _nearest_and_tie(camera, ray, t, owner[tri], depth)
    mirrored = np.array([obj.mirrored for obj in scene.objects] + [False])
    shape = (len(offsets), height, width)
    nearest, tie = ([a[k] for a in (ray, t, u, v, det, tri)] for k in (first, second))
    return PixelHits(np.array(offsets), *_fill(shape, o, d, *nearest, owner, local, mirrored),
                     *_fill(shape, o, d, *tie, owner, local, mirrored))


# --------------------------------------------------------------------------- the passes
def _objects_hit(scene, hits):
    """``(index, object, mask)`` for every object some sample hits; ``mask`` (S, H, W) bool."""
    for k in np.unique(hits.object_index[hits.object_index >= 0]):
        yield int(k), scene.objects[int(k)], hits.object_index == k


def _interpolate(hits, mask, mesh, values):
    """Barycentric interpolation of per-vertex ``values`` (V, C) at the hits under ``mask``: (N, C) float64."""
    corners = mesh.indices[hits.triangle[mask]].astype(np.int64)
    return np.einsum("nk,nkc->nc", hits.barycentric[mask], np.asarray(values, dtype=np.float64)[corners])


def _per_vertex(scene, hits, channels, values_of):
    """(S, H, W, channels) float64: ``values_of(object)`` (V, channels) interpolated at the hits, 0 where none."""
    out = np.zeros(hits.object_index.shape + (channels,))
    for _, obj, mask in _objects_hit(scene, hits):
        out[mask] = _interpolate(hits, mask, obj.mesh, values_of(obj))
    return out


def _positions(obj):
    """The object's vertex positions (V, 3) float32 [m], in its own frame."""
    return obj.mesh.positions


def _uvs(obj):
    """The object's uvs (V, 2) float32; ValueError where it has none."""
    if obj.mesh.uvs is None:
        raise ValueError(f"object {obj.name!r} has no uvs: its mesh cannot give the 'uv' pass")
    return obj.mesh.uvs


def _bounds(mesh):
    """``(lo, extent)`` of the mesh's positions per axis, each (3,) float64 [m]."""
    lo, hi = mesh.box
    return lo, hi - lo


def _nocs(scene, hits, oc):
    """(S, H, W, 3) float64: the normalised object coordinates of the object points ``oc`` (S, H, W, 3) [m]."""
    out = np.zeros_like(oc)
    for _, obj, mask in _objects_hit(scene, hits):
        lo, extent = _bounds(obj.mesh)
        flat = extent == 0.0
        out[mask] = np.where(flat, 0.5, np.clip((oc[mask] - lo) / np.where(flat, 1.0, extent), 0.0, 1.0))
    return out


def _normal(scene, hits):
    """(S, H, W, 3) float64: the world unit shading normal (see the module), NaN under a normal map."""
    out = np.zeros(hits.object_index.shape + (3,))
    for _, obj, mask in _objects_hit(scene, hits):
        n = _interpolate(hits, mask, obj.mesh, obj.mesh.normals) @ obj.normal_matrix.T
        if obj.material.two_sided:
            n = np.where(hits.front[mask][:, None], n, -n)
        out[mask] = np.nan if obj.material.normal_map is not None else safe_normalize(n)[1]
    return out


def _ids(scene, hits, name):
    """(S, H, W) int64: the hit objects' ``instance_id`` or ``category`` (``name``), 0 where none."""
    values = np.array([getattr(obj, "instance_id" if name == "instance" else "category") for obj in scene.objects]
                      + [0], dtype=np.int64)
    return values[hits.object_index]  # index -1: the trailing 0


def _flow(scene, hits, other, oc):
    """(S, H, W, 2) float64 [px]: the flow of the object points ``oc`` (S, H, W, 3) to ``other`` (see the module)."""
    h, w = hits.object_index.shape[1:]
    out = np.zeros(oc.shape[:-1] + (2,))
    centre = np.stack(np.broadcast_arrays(np.arange(w)[None, :] + 0.5, np.arange(h)[:, None] + 0.5), axis=-1)
    for k, _, mask in _objects_hit(scene, hits):
        pose = other.objects[k].pose
        xp, yp, ahead = _project(other.camera, w, h, oc[mask] @ pose[:3, :3].T + pose[:3, 3])
        out[mask] = np.where(ahead[:, None], np.stack([xp, yp], axis=-1) - centre[mask.nonzero()[1:]], np.nan)
    return out


def _check_names(names):
    """The pass names as a list; ValueError for one not in `PASS_NAMES`."""
    names = [names] if isinstance(names, str) else list(names)
    unknown = [n for n in names if n not in PASS_NAMES]
    if unknown:
        raise ValueError(f"unknown passes {unknown}: the passes are {', '.join(PASS_NAMES)}")
    return names


def twin_passes(scene, hits, names, next_scene=None, previous_scene=None, which="nearest"):
    """The float64 twin of the frame passes at every sample.

    Parameters
    ----------
    scene : glphong.Scene
        The scene `cast_pixels` cast ``hits`` in.
    hits : PixelHits
    names : str or iterable of str
        Passes, from `PASS_NAMES`.
    next_scene, previous_scene : glphong.Scene, optional
        The scene at the next (previous) frame, with the same meshes at the same indices: needed by ``flow``
        (``backward_flow``).
    which : {'nearest', 'tie'}
        Evaluate the nearest hits, or the tie hits (0 where a sample has no tie).

    Returns
    -------
    dict of str to ndarray
        Pass name to (S, H, W) or (S, H, W, C) array: float64 (depth and distance [m], normal and normal_camera
        (C = 3), uv (2), object_coordinates [m] (3), nocs (3), flow and backward_flow [px] (2)); int64 for
        instance and category.  0 where a sample hits nothing; NaN where unchecked (see the module).

    Raises
    ------
    ValueError
        An unknown pass; ``uv`` of a hit object without uvs; a flow without its scene, or with a scene whose
        objects do not correspond.
    """
    names = _check_names(names)
    others = {n: next_scene if n == "flow" else previous_scene for n in names if n in _OTHER_SCENE}
    for name, other in others.items():
        check_corresponds(scene, other, name, _OTHER_SCENE[name])
    if _validate.choice("which", which, ("nearest", "tie")) == "tie":
        hits = hits.ties()
    hit = hits.object_index >= 0
    camera = scene.camera
    out, oc = {}, None
    if {"object_coordinates", "nocs"} & set(names) or others:
        oc = _per_vertex(scene, hits, 3, _positions)
    for name in names:
        if name == "depth":
            out[name] = np.where(hit, dot(hits.position - camera.position, -camera.pose[:3, 2]), 0.0)
        elif name == "distance":
            out[name] = np.where(hit, hits.t, 0.0)
        elif name in ("normal", "normal_camera"):
            n = _normal(scene, hits)
            out[name] = n if name == "normal" else n @ (_GL_TO_CV @ camera.pose[:3, :3].T).T
        elif name == "uv":
            out[name] = _per_vertex(scene, hits, 2, _uvs)
        elif name in _ID_PASSES:
            out[name] = _ids(scene, hits, name)
        elif name == "object_coordinates":
            out[name] = oc
        elif name == "nocs":
            out[name] = _nocs(scene, hits, oc)
        else:
            out[name] = _flow(scene, hits, others[name], oc)
    return out


# --------------------------------------------------------------------------- the band
def _rounding(scene, obj, name):
    """The float32 rounding term of pass ``name`` (not a flow) on ``obj``, (C,) float64 (see the module)."""
    m = float(np.max(np.abs(obj.mesh.positions)))
    if name in ("depth", "distance"):
        world = obj.mesh.positions.astype(np.float64) @ obj.pose[:3, :3].T + obj.pose[:3, 3]
        return np.array([32.0 * EPS * (np.max(np.abs(world)) + np.linalg.norm(scene.camera.position))])
    if name == "object_coordinates":
        return np.full(3, 8.0 * EPS * m)
    if name == "nocs":
        extent = _bounds(obj.mesh)[1]
        return np.where(extent > 0.0, 8.0 * EPS * m / np.where(extent > 0.0, extent, 1.0), 0.0)
    if name == "uv":
        return np.full(2, 8.0 * EPS * (0.0 if obj.mesh.uvs is None else float(np.max(np.abs(obj.mesh.uvs)))))
    return np.full(3, 16.0 * EPS)  # normal, normal_camera


def _per_object(scene, hits, value_of, channels):
    """``value_of(object)`` (channels,) at every hit, 0 where none: (S, H, W, channels) float64."""
    table = np.array([np.reshape(value_of(obj), channels) for obj in scene.objects] + [np.zeros(channels)])
    return table[hits.object_index]  # index -1: the trailing zeros


def _sample_range(scene, hits, name, values, other):
    """``(low, high)`` of pass ``name`` at every sample, (S, H, W) or (S, H, W, C): ``values`` widened by its float32
    rounding; for a flow, its extremes at ``oc`` and ``oc +- r e_k`` (NaN where the flow is NaN)."""
    if name not in _OTHER_SCENE:
        channels = values.shape[-1] if values.ndim > 3 else 1
        term = _per_object(scene, hits, lambda obj: _rounding(scene, obj, name), channels)
        term = term if values.ndim > 3 else term[..., 0]
        return values - term, values + term
    oc = _per_vertex(scene, hits, 3, _positions)
    r = _per_object(scene, hits, lambda obj: 8.0 * EPS * np.max(np.abs(obj.mesh.positions)), 1)
    low, high = values.copy(), values.copy()
    for step in np.concatenate([np.eye(3), -np.eye(3)]):
        moved = _flow(scene, hits, other, oc + r * step)
        low, high = np.fmin(low, moved), np.fmax(high, moved)
    nan = np.isnan(values)
    return np.where(nan, np.nan, low), np.where(nan, np.nan, high)


def _id_sets(near, tie):
    """(H, W, K) int64: the distinct ids of ``near`` (S, H, W) and of ``tie`` (S, H, W; -1 for none), padded with -1."""
    none = np.iinfo(np.int64).max
    values = np.sort(np.concatenate([near, tie]), axis=0)
    repeated = np.zeros_like(values, dtype=bool)
    repeated[1:] = values[1:] == values[:-1]
    values = np.sort(np.where(repeated | (values < 0), none, values), axis=0)
    values = values[:max(1, int(np.max(np.sum(values != none, axis=0))))]
    return np.moveaxis(np.where(values == none, -1, values), 0, -1)


def pass_bands(scene, hits, names, next_scene=None, previous_scene=None, nearest=None):
    """The interval each GPU pass must lie in at every pixel.

    Parameters
    ----------
    scene, hits, names, next_scene, previous_scene
        As `twin_passes` takes them.
    nearest : dict, optional
        ``twin_passes(scene, hits, names, next_scene, previous_scene)`` where the caller has it (not computed again).

    Returns
    -------
    dict of str to tuple or ndarray
        Float passes: ``(low, high)``, each (H, W) or (H, W, C) float64, the min and max over the samples and their
        ties widened by the float32 rounding of the module; NaN where unchecked.  ``instance`` and ``category``:
        (H, W, K) int64, the ids the GPU may show (those of the samples, 0 for a sample that hits nothing, and of
        their ties), padded with -1.
    """
    names = _check_names(names)
    views = (hits, hits.ties())
    if nearest is None:
        nearest = twin_passes(scene, hits, names, next_scene, previous_scene)
    values = [nearest, twin_passes(scene, views[1], names, next_scene, previous_scene)]
    tie = hits.tie_object_index >= 0
    others = {"flow": next_scene, "backward_flow": previous_scene}
    out = {}
    for name in names:
        if name in _ID_PASSES:
            out[name] = _id_sets(values[0][name], np.where(tie, values[1][name], -1))
            continue
        (low, high), (tie_low, tie_high) = (_sample_range(scene, view, name, v[name], others.get(name))
                                            for view, v in zip(views, values))
        mask = tie if low.ndim == 3 else tie[..., None]
        out[name] = (np.min(np.minimum(low, np.where(mask, tie_low, low)), axis=0),
                     np.max(np.maximum(high, np.where(mask, tie_high, high)), axis=0))
    return out
