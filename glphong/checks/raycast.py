"""A converged float64 reference image of exact analytic geometry (docs/design.md sections 4 and 7, layer 3).

The GPU draws tessellated meshes sampled once at each pixel centre; this module ray
casts the *true* surfaces (`Sphere`, `Plane`) with ``samples_per_axis**2`` rays per
pixel and shades every hit with the numpy twin `glphong.reference.shade_point`, so
that an image can be scored against geometry that has no tessellation error and a
pixel value that is the pixel's average radiance.  It is the reference of the
work-precision benchmark (error of a render vs its cost).

Conventions
-----------
- Rays: `PerspectiveCamera.sample_rays`: pixel (row j, column i) with row 0 at the top,
  offset ``(ox, oy)`` in pixel units measured rightwards and downwards from the pixel's
  top-left corner; ``(0.5, 0.5)`` is the pixel centre (`PerspectiveCamera.pixel_rays`).  `render_reference` uses the stratified
  regular grid ``((i + 0.5)/n, (j + 0.5)/n)``, ``i, j = 0..n-1`` (`stratified_offsets`).
- Hits: the nearest intersection with ``t > 1e-12`` wins.  As the rasteriser clips, only
  hits whose depth along the camera's viewing axis lies in ``[znear, zfar]`` count.
- Shading: exactly the twin.  A `glphong.Scene` is built from the camera, the lights and
  the ambient light, each object's material is added with a dummy one-triangle mesh, and
  each hit is shaded by ``reference.shade_point(p, n, valid, u['u_eye'], key, u, material)`` with
  ``u = binding(scene).uniform_values(index, key, width / height)`` cast to float64: the very
  uniforms the GPU receives, so material and light parameters are the float32-rounded
  inputs (relative rounding <= 2^-24) while positions and normals are exact float64.
  The point ``p = o + t d`` and the outward normal come from the exact surface.
- Two-sided shading: where the program key is two-sided (the material is two-sided and
  lit) and ``n . (eye - p) < 0`` the normal is flipped toward the viewer; for exact
  geometry the front face is the side the normal points to (mesh_fragment.glsl flips on
  ``!gl_FrontFacing``, i.e. the winding; for a consistently wound closed mesh seen from
  outside the two agree).
- Pixel value: the mean radiance over *all* samples of the pixel, a missed sample
  counting 0 (black background); ``coverage`` is the fraction of samples that hit.
"""
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.scene.camera import Camera
from glphong.scene.geometry import MeshData
from glphong.lights import AmbientLight
from glphong.materials import Material
from glphong.definitions.table import uniform_as
from glphong.checks.reference import safe_normalize, shade_point
from glphong.scene.scene import Scene
from glphong.shaders.binding import binding

__all__ = ["Sphere", "Plane", "AnalyticObject", "RayCastImage", "stratified_offsets",
           "render_reference", "compare_to_reference", "T_MIN", "CHUNK_RAYS"]

#: hits at ``t <= T_MIN`` (in units of the ray direction's length) are ignored
T_MIN = 1e-12
#: rays processed at once by `render_reference` (peak memory measured ~90 MB at 256x256 px, 4x4 samples;
#: ~140 MB at 1024x1024 px, 8x8 samples)
CHUNK_RAYS = 1 << 18


def _unit(name, value):
    """A non-zero 3-vector normalised with the scaled normalisation, as a tuple of float."""
    a = np.asarray(_validate.vec3(name, value, nonzero=True))
    a = a / np.max(np.abs(a))
    return tuple(float(c) for c in a / np.linalg.norm(a))


def _rays(origins, dirs):
    origins = np.asarray(origins, dtype=np.float64)
    dirs = np.asarray(dirs, dtype=np.float64)
    if dirs.ndim != 2 or dirs.shape[1] != 3:
        raise ValueError(f"dirs must have shape (N, 3) (got {dirs.shape})")
    return np.broadcast_to(origins, dirs.shape), dirs


def _bounds(t_min, t_max, n):
    lo = np.broadcast_to(np.asarray(T_MIN if t_min is None else t_min, dtype=np.float64), (n,))
    hi = np.broadcast_to(np.asarray(np.inf if t_max is None else t_max, dtype=np.float64), (n,))
    return np.maximum(lo, T_MIN), hi


@dataclass(frozen=True)
class Sphere:
    """A sphere.

    Parameters
    ----------
    center : (3,) array_like
        Centre [m].
    radius : float
        Radius [m], > 0.
    """

    center: tuple
    radius: float

    def __post_init__(self):
        object.__setattr__(self, "center", _validate.vec3("center", self.center))
        object.__setattr__(self, "radius", _validate.scalar("radius", self.radius, low_inclusive=False))

    def intersect(self, origins, dirs, t_min=None, t_max=None):
        """Nearest ray parameter of a hit.

        Parameters
        ----------
        origins : (N, 3) or (3,) array_like
            Ray origins [m].
        dirs : (N, 3) array_like
            Ray directions, any non-zero length; ``t`` is in units of their length.
        t_min, t_max : float or (N,) array_like, optional
            Only hits with ``max(t_min, 1e-12) < t <= t_max`` count (defaults 1e-12 and inf).

        Returns
        -------
        (N,) float64 ndarray
            The smallest valid root, ``inf`` where the ray misses.

        Notes
        -----
        Evaluated without cancellation (Ray Tracing Gems, ch. 7): the squared half chord is
        ``(r - |f|)(r + |f|) / (d.d)`` with ``f`` the centre's offset from the ray's point
        of closest approach ``t_c``, and the root nearer 0 is ``c / ((d.d) q)`` with
        ``q = t_c + sign(t_c) s``, ``c = (|oc| - r)(|oc| + r)``.  A tangent ray hits.
        """
        o, d = _rays(origins, dirs)
        lo, hi = _bounds(t_min, t_max, len(d))
        oc = o - np.asarray(self.center)
        a = np.einsum("ij,ij->i", d, d)
        tc = -np.einsum("ij,ij->i", oc, d) / a
        f = oc + tc[:, None] * d
        fl = np.sqrt(np.einsum("ij,ij->i", f, f))
        r = self.radius
        h2 = (r - fl) * (r + fl) / a
        hit = h2 >= 0
        s = np.sqrt(np.where(hit, h2, 0.0))
        ocl = np.sqrt(np.einsum("ij,ij->i", oc, oc))
        c = (ocl - r) * (ocl + r)
        q = tc + np.where(tc >= 0, s, -s)
        with np.errstate(divide="ignore", invalid="ignore"):
            other = np.where(q != 0, c / (a * q), 0.0)
        t0, t1 = np.minimum(q, other), np.maximum(q, other)
        t = np.where(t0 > lo, t0, np.where(t1 > lo, t1, np.inf))
        return np.where(hit & (t <= hi), t, np.inf)

    def normal_at(self, points):
        """Outward unit normals ``(p - c) / |p - c|`` at points on the sphere, (N, 3) float64."""
        _, n, _ = safe_normalize(np.asarray(points, dtype=np.float64) - np.asarray(self.center))
        return n


@dataclass(frozen=True)
class Plane:
    """A plane, infinite or a square.

    Parameters
    ----------
    point : (3,) array_like
        A point of the plane; the square's centre [m].
    normal : (3,) array_like
        Normal, any non-zero length (stored normalised); it defines the front side.
    half_extent : float or None
        None: the infinite plane.  Otherwise the square ``|(x - point).u| <= half_extent``,
        ``|(x - point).v| <= half_extent`` (side ``2 half_extent``), with the in-plane axes
        of `axes`.

    Notes
    -----
    `axes` is deterministic: ``a`` is the world axis e_x, e_y or e_z with the smallest
    ``|n_k|`` (the first one on ties), ``u = normalise(a - (a.n) n)``, ``v = n x u``.  For
    ``n = +-e_z`` that gives ``u = e_x`` and ``v = +-e_y`` (the square's sides are parallel to
    the world x and y axes); for ``n = +-e_y``, ``u = e_x``.
    """

    point: tuple
    normal: tuple
    half_extent: float = None

    def __post_init__(self):
        object.__setattr__(self, "point", _validate.vec3("point", self.point))
        object.__setattr__(self, "normal", _unit("normal", self.normal))
        if self.half_extent is not None:
            object.__setattr__(self, "half_extent",
                               _validate.scalar("half_extent", self.half_extent, low_inclusive=False))

    @property
    def axes(self):
        """The in-plane orthonormal axes ``(u, v)``, two (3,) float64 arrays (see Notes)."""
        n = np.asarray(self.normal)
        a = np.zeros(3)
        a[int(np.argmin(np.abs(n)))] = 1.0
        u = a - (a @ n) * n
        u /= np.linalg.norm(u)
        return u, np.cross(n, u)

    def intersect(self, origins, dirs, t_min=None, t_max=None):
        """Ray parameter of the hit, ``inf`` where missed (parallel rays miss); see `Sphere.intersect`."""
        o, d = _rays(origins, dirs)
        lo, hi = _bounds(t_min, t_max, len(d))
        n = np.asarray(self.normal)
        p0 = np.asarray(self.point)
        denom = d @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((p0 - o) @ n) / denom
        hit = (denom != 0) & np.isfinite(t) & (t > lo) & (t <= hi)
        if self.half_extent is not None:
            u, v = self.axes
            x = o + np.where(hit, t, 0.0)[:, None] * d - p0
            h = self.half_extent
            hit &= (np.abs(x @ u) <= h) & (np.abs(x @ v) <= h)
        return np.where(hit, t, np.inf)

    def normal_at(self, points):
        """The plane's unit normal at every point, (N, 3) float64."""
        return np.tile(np.asarray(self.normal), (len(np.asarray(points)), 1))


@dataclass(frozen=True)
class AnalyticObject:
    """An exact surface shaded with a glphong material.

    Parameters
    ----------
    shape : Sphere or Plane
    material : glphong.materials.Material
    """

    shape: object
    material: Material

    def __post_init__(self):
        if not isinstance(self.shape, (Sphere, Plane)):
            raise TypeError(f"shape must be a glphong.checks.raycast.Sphere or Plane (got {type(self.shape).__name__})")
        if not isinstance(self.material, Material):
            raise TypeError(f"material must be a glphong material (got {type(self.material).__name__})")


@dataclass(frozen=True)
class RayCastImage:
    """A converged reference image.

    Attributes
    ----------
    radiance : (H, W, 3) float64 ndarray
        Mean radiance over all samples of each pixel [W/(m^2 sr)], missed samples counting 0.
    coverage : (H, W) float64 ndarray
        Fraction of the pixel's samples that hit an object, in [0, 1].
    interior : (H, W) bool ndarray
        Every sample hit, and hit the same object: pixels away from silhouettes and from
        boundaries between objects.
    object_index : (H, W) int64 ndarray
        The object of an `interior` pixel (its index in ``objects``), -1 elsewhere.
    samples_per_axis : int
        The pixel was sampled on an ``n x n`` stratified grid.
    """

    radiance: np.ndarray
    coverage: np.ndarray
    interior: np.ndarray
    object_index: np.ndarray
    samples_per_axis: int


def stratified_offsets(n):
    """The regular stratified grid of sub-pixel offsets ``((i + 0.5)/n, (j + 0.5)/n)``.

    Returns
    -------
    (n*n, 2) float64 ndarray
        ``(ox, oy)`` pairs, row-major in ``(j, i)``; ``ox`` rightwards, ``oy`` downwards.
    """
    n = _validate.positive_int("samples_per_axis", n)
    c = (np.arange(n) + 0.5) / n
    oy, ox = np.meshgrid(c, c, indexing="ij")
    return np.stack([ox.ravel(), oy.ravel()], axis=-1)


def _dummy_mesh():
    return MeshData([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0.0, 0.0, 1.0]] * 3, [[0, 1, 2]])


def render_reference(camera, objects, lights=(), ambient=None, width=256, height=256, samples_per_axis=4):
    """Ray cast exact geometry with ``samples_per_axis**2`` stratified rays per pixel, shaded by the twin.

    Parameters
    ----------
    camera : PerspectiveCamera
    objects : sequence of AnalyticObject
    lights : sequence of PointLight, UnattenuatedPointLight or DirectionalLight
    ambient : AmbientLight, optional
    width, height : int
        Image size [px].
    samples_per_axis : int
        ``n``: the pixel is sampled on the ``n x n`` grid of `stratified_offsets`.

    Returns
    -------
    RayCastImage

    Notes
    -----
    Vectorised over chunks of whole rows of about `CHUNK_RAYS` rays.  Measured on 2 cores
    (numpy float64): 256x256 px at 4x4 samples (1.05 M rays), sphere + square plane, two
    point lights and an ambient light, Phong and Lambert: 0.86-1.34 s (1 sample: 0.065 s);
    128x128 px, one Phong sphere, one light: 0.20 s at 4x4, 0.74 s at 8x8.
    """
    if not isinstance(camera, Camera):
        raise TypeError(f"camera must be a glphong camera such as PerspectiveCamera (got {type(camera).__name__})")
    if ambient is not None and not isinstance(ambient, AmbientLight):
        raise TypeError(f"ambient must be a glphong.AmbientLight or None (got {type(ambient).__name__})")
    objects = list(objects)
    if not objects:
        raise ValueError("objects must hold at least one AnalyticObject")
    for k, obj in enumerate(objects):
        if not isinstance(obj, AnalyticObject):
            raise TypeError(f"objects[{k}] must be a glphong.checks.raycast.AnalyticObject (got {type(obj).__name__})")
    width = _validate.positive_int("width", width)
    height = _validate.positive_int("height", height)
    n = _validate.positive_int("samples_per_axis", samples_per_axis, high=1024)

    scene = Scene(camera, lights, ambient)
    dummy = _dummy_mesh()
    shading = []
    for index, obj in enumerate(objects):
        scene_obj = scene.add(dummy, obj.material)
        key = binding(scene).program_key(scene_obj)
        u = {k: uniform_as(v, np.float64) for k, v in binding(scene).uniform_values(index, key, width / height).items()}
        shading.append((key, u))

    offsets = stratified_offsets(n)
    s = len(offsets)
    eye = camera.eye  # homogeneous: the view vector at p is e - w p
    forward = -camera.pose[:3, 2]
    radiance = np.zeros((height, width, 3))
    coverage = np.zeros((height, width))
    interior = np.zeros((height, width), bool)
    object_index = np.full((height, width), -1, np.int64)
    rows_per_chunk = max(1, CHUNK_RAYS // (width * s))
    for r0 in range(0, height, rows_per_chunk):
        rows = slice(r0, min(r0 + rows_per_chunk, height))
        o, d = camera.sample_rays(width, height, offsets, rows)
        shape = d.shape[:-1]  # (R, W, S)
        o = np.broadcast_to(o, d.shape).reshape(-1, 3)  # one origin (perspective) or one per ray (orthographic)
        d = d.reshape(-1, 3)
        # the rasteriser keeps depths (along the viewing axis) in [znear, zfar]
        cos = d @ forward
        t = np.stack([obj.shape.intersect(o, d, camera.znear / cos, camera.zfar / cos) for obj in objects])
        best = np.argmin(t, axis=0)
        t_best = t[best, np.arange(len(d))]
        hit = np.isfinite(t_best)
        best = np.where(hit, best, -1)
        sample = np.zeros((len(d), 3))
        for k, (obj, (key, u)) in enumerate(zip(objects, shading)):
            sel = np.flatnonzero(best == k)
            if not len(sel):
                continue
            p = o[sel] + t_best[sel, None] * d[sel]
            nrm = obj.shape.normal_at(p)
            if key.two_sided:
                back = np.einsum("ij,ij->i", nrm, eye[:3] - p * eye[3]) < 0
                nrm[back] = -nrm[back]
            sample[sel] = shade_point(p, nrm, np.ones(len(sel), bool), u.get("u_eye"), key, u, objects[k].material)
        radiance[rows] = sample.reshape(*shape, 3).sum(axis=2) / s
        best = best.reshape(shape)
        coverage[rows] = (best >= 0).sum(axis=2) / s
        same = np.all(best == best[..., :1], axis=2) & (best[..., 0] >= 0)
        interior[rows] = same
        object_index[rows] = np.where(same, best[..., 0], -1)
    return RayCastImage(radiance=radiance, coverage=coverage, interior=interior, object_index=object_index,
                        samples_per_axis=n)


def compare_to_reference(image, image_mask, reference, relative_floor=1e-6):
    """Score an image against a converged `RayCastImage`, interior and silhouette pixels apart.

    Parameters
    ----------
    image : (H, W, 3) array_like
        Radiance of the render under test (e.g. ``Frame.radiance``); read as float64.
    image_mask : (H, W) bool array_like
        Its coverage (e.g. ``Frame.mask``); ``image`` counts as 0 where it is False.
    reference : RayCastImage
    relative_floor : float
        Per-pixel relative errors are taken where ``|ref| > relative_floor * max |ref|``.

    Returns
    -------
    dict
        ``interior_pixels``: pixels that are `RayCastImage.interior` and covered in
        ``image_mask``; the figures below are over them, with ``|x|`` the Euclidean norm
        over the three channels:

        - ``relative_rms``: ``sqrt(sum |img - ref|^2 / sum |ref|^2)``;
        - ``p99_relative``, ``max_relative``: 99th percentile and maximum of the per-pixel
          ``|img - ref| / |ref|``, over the interior pixels with
          ``|ref| > relative_floor * max |ref|`` (``max`` over the interior; darker pixels,
          e.g. ambient-free regions facing away from every light, have no meaningful
          relative error and are left out); ``relative_pixels`` counts them.  Near a shadow
          terminator (``n.l -> 0``, no ambient) the radiance goes to 0 continuously, so with
          the default floor the pixels the terminator crosses have relative errors up to 1
          (the centre sample unlit, a few of the pixel's samples lit) and decide
          ``p99_relative`` and ``max_relative``; a floor of 1e-2 leaves them out.

        ``silhouette_pixels``: every pixel that is neither interior nor background
        (background: no sample hit and not covered in ``image_mask``): partially covered
        pixels, pixels on a boundary between objects, and pixels where ``image_mask`` differs
        from ``coverage > 0.5`` or from full coverage.  ``silhouette_relative_mae``: their
        mean ``|img - ref|`` divided by the mean ``|ref|`` over the interior pixels (over the
        silhouette pixels where there is no interior pixel); NaN where undefined.
        ``background_pixels`` counts the rest.
    """
    if not isinstance(reference, RayCastImage):
        raise TypeError(f"reference must be a glphong.checks.raycast.RayCastImage (got {type(reference).__name__})")
    relative_floor = _validate.scalar("relative_floor", relative_floor)
    ref = reference.radiance
    img = np.asarray(image, dtype=np.float64)
    mask = np.asarray(image_mask, dtype=bool)
    if img.shape != ref.shape:
        raise ValueError(f"image must have the reference's shape {ref.shape} (got {img.shape})")
    if mask.shape != ref.shape[:2]:
        raise ValueError(f"image_mask must have shape {ref.shape[:2]} (got {mask.shape})")
    img = np.where(mask[..., None], img, 0.0)
    interior = reference.interior & mask
    background = (reference.coverage == 0) & ~mask
    silhouette = ~interior & ~background
    err = np.linalg.norm(img - ref, axis=-1)
    mag = np.linalg.norm(ref, axis=-1)
    out = {"interior_pixels": int(interior.sum()), "silhouette_pixels": int(silhouette.sum()),
           "background_pixels": int(background.sum())}
    nan = float("nan")
    if interior.any():
        den = np.sum(mag[interior] ** 2)
        out["relative_rms"] = float(np.sqrt(np.sum(err[interior] ** 2) / den)) if den > 0 else nan
        bright = interior & (mag > relative_floor * mag[interior].max())
        rel = err[bright] / np.maximum(mag[bright], np.finfo(np.float64).tiny)
        out["relative_pixels"] = int(bright.sum())
        out["p99_relative"] = float(np.percentile(rel, 99)) if rel.size else nan
        out["max_relative"] = float(rel.max()) if rel.size else nan
        scale = mag[interior].mean()
    else:
        out.update(relative_rms=nan, relative_pixels=0, p99_relative=nan, max_relative=nan)
        scale = mag[silhouette].mean() if silhouette.any() else 0.0
    out["silhouette_relative_mae"] = float(err[silhouette].mean() / scale) if silhouette.any() and scale > 0 else nan
    return out
