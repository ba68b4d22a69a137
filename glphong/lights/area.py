"""The area lights 'rect' and 'polygon': one-sided uniform emitters (docs/design.md section 13; GLSL:
``glsl/lights/rect.glsl``, ``glsl/lights/polygon.glsl``, library ``glsl/area.glsl``; twin `glphong.twin.area`).

A Lambertian emitter of radiance ``L`` [W/(m^2 sr)] over a planar convex polygon, one-sided.  At a surface point
``x`` with normal ``n``:

- the irradiance ``E(n) = L integral_polygon (n.w)^+ dw`` exactly, by Lambert's edge formula after clipping the
  polygon to the surface's hemisphere (`area_polygon_cosine`);
- the lecture's Phong lobe ``integral max(r.w, 0)^q L [n.w > 0] dw`` exactly for integer ``q``, by Arvo's edge
  recurrences after clipping to both hemispheres (`area_polygon_lobe`);
- for every other term, the midpoint rule over ``samples^2`` cells (a parallelogram) or ``samples^2`` sub-triangles of
  each triangle of the fan (a polygon): ``E_k = L cos_l A_k / d_k^2`` toward each cell's centre.

Far away the light is a point of intensity ``L A cos(theta_l)`` [W/sr]: ``E -> L A cos(theta_l) cos(theta) / d^2``
(tested).  Its power is ``pi L A``.
"""
import numpy as np

from glphong.core import validate as _validate
from glphong.lights.extended import CENTER, RADIANCE, SAMPLES, ExtendedLight, extended_cases
from glphong.definitions.light import GlslFile, Param, sensitivity_band
from glphong.materials.lambert import Lambert
from glphong.twin.area import (area_clip, area_clip_rounding, area_clipped_cosine, area_clipped_cosine_of,
                               area_clipped_lobe, area_cosine_rounding, area_lobe_rounding, area_triangle_sample,
                               polygon_arrays)
from glphong.twin.functions import dot as _dot, safe_normalize
from glphong.twin.quadrature import polygon_integral

__all__ = ["RectLight", "PolygonLight", "MAX_POLYGON_VERTICES"]

#: vertices a PolygonLight may have
MAX_POLYGON_VERTICES = 8



class _Polygonal:
    """What the polygon kinds share, given ``polygon_of(x, p)`` (their GLSL's ``<kind>_polygon``): the closed forms'
    twins (rect.glsl's and polygon.glsl's ``_irradiance`` and ``_lobe``) and their bands, the generic sensitivity band
    (inputs moved by a few ulps) plus the float32 rounding of the edge formulas and the clips themselves
    (`area_cosine_rounding`, `area_lobe_rounding`, `area_clip_rounding`), which no input perturbation shows.  The
    sensitivity band takes the shortcuts the closed forms allow (`sensitivity_band`): the radiance a factor, the
    rect's centre moved with ``x`` (``offset_uniform``), each move one way (``one_sided``: the closed forms are
    continuous, and smooth where not 0); the irradiance's moves of the normal reuse the polygon of ``x`` and its
    edges (`area_clipped_cosine_of`)."""

    def irradiance(self, x, n, p):
        return p.radiance * area_clipped_cosine(*self.polygon_of(x, p), n)[:, None]

    def lobe(self, x, n, r, q, p):
        return p.radiance * area_clipped_lobe(*self.polygon_of(x, p), n, r, q)[:, None]

    #: the 'vec3' uniform the twin reads only through ``uniform - x`` (`sensitivity_band`'s ``offset``), or None
    offset_uniform = None

    def irradiance_band(self, x, n, p, constants):
        polygon = self.polygon_of(x, p)
        cosine = area_clipped_cosine_of(*polygon)  # the moves of n see the polygon of x

        def evaluate(x_, p_, n_):
            if p_ is p and x_.shape == x.shape and np.array_equal(x_, x):
                return p.radiance * cosine(n_)[:, None]
            return self.irradiance(x_, n_, p_)

        low, high = sensitivity_band(evaluate, x, p, self.perturbed_uniforms(), constants, (n,), factors=("radiance",),
                                     offset=self.offset_uniform, one_sided=True)
        clipped = area_clip(*polygon, n)
        slack = p.radiance * (area_cosine_rounding(*clipped, n) + area_clip_rounding(*polygon, n))[:, None]
        return np.maximum(low - slack, 0.0), high + slack

    def lobe_band(self, x, n, r, q, p, constants):
        """Also the clips' slide: by the horizon, where the lobe is not 0 (`area_clip_rounding` with ``lobe``), and by
        the lobe's own plane, where it is."""
        low, high = sensitivity_band(lambda x_, p_, n_, r_: self.lobe(x_, n_, r_, q, p_), x, p,
                                     self.perturbed_uniforms(), constants, (n, r), factors=("radiance",),
                                     offset=self.offset_uniform, one_sided=True)
        polygon = self.polygon_of(x, p)
        by_n = area_clip(*polygon, n)
        clipped = area_clip(*by_n, r)
        slack = area_lobe_rounding(*clipped, r, q) + area_clip_rounding(*polygon, n, lobe=(r, q)) \
            + area_clip_rounding(*by_n, r)
        slack = p.radiance * slack[:, None]
        return np.maximum(low - slack, 0.0), high + slack


class RectLight(_Polygonal, ExtendedLight):
    """A one-sided uniform parallelogram light: corners ``center +- u/2 +- v/2``, emitting along ``u x v``.

    At a point ``x`` with normal ``n``: ``E(n) = L integral (n.w)^+ dw`` over the polygon as seen from ``x``, exactly
    (Lambert's edge formula, clipped to the horizon); the lecture's Phong lobe ``integral max(r.w, 0)^q L [n.w > 0]
    dw`` exactly for integer ``q`` (Arvo's edge recurrences); every other term by the midpoint rule, ``E_k = L cos_l
    A_k / d_k^2`` toward each of its cells.  Its power is ``pi L A``.

    Parameters
    ----------
    center : (3,) array_like
        Its centre [m].
    u, v : (3,) array_like
        Its edge vectors [m] (not parallel); it emits toward the side ``u x v`` points to.
    radiance : float or (3,) array_like
        ``L`` [W/(m^2 sr)], uniform and the same in every direction of its front side.
    samples : int
        Cells per side of the sampled method (the terms without a closed form), 1 to 64 (default 4: 16 cells).
    """

    name = "rect"
    loop_order = 4
    params = (CENTER,
              Param("u", "vec3", low=-np.inf, unit="m", doc="first edge vector"),
              Param("v", "vec3", low=-np.inf, unit="m", doc="second edge vector; emits along u x v"),
              RADIANCE, SAMPLES)
    glsl = GlslFile("lights/rect.glsl")
    uses = ("angle", "area")
    integrals = ("irradiance", "lobe")
    exact_integrals = ("irradiance", "lobe")

    def check(self):
        super().check()
        if not np.linalg.norm(np.cross(self.u, self.v)) > 0.0:
            raise ValueError(f"RectLight: u and v must span a parallelogram (got u={self.u}, v={self.v}, parallel or zero)")

    @classmethod
    def example(cls, **overrides):
        """A 0.6 m square 1 m above the origin, emitting down (toward -z)."""
        return cls(**({"center": (0.0, 0.0, 1.0), "u": (0.0, 0.6, 0.0), "v": (0.6, 0.0, 0.0), "radiance": 0.5}
                      | overrides))

    def area(self):
        """``|u x v|`` [m^2]."""
        return float(np.linalg.norm(np.cross(self.u, self.v)))

    def power(self):
        """``pi L A`` [W] (3,): a one-sided Lambertian emitter."""
        return np.pi * np.asarray(self.radiance) * self.area()

    def corners(self):
        """The corners (4, 3), counter-clockwise seen from the front."""
        c, u, v = (np.asarray(a, dtype=np.float64) for a in (self.center, self.u, self.v))
        a = c - 0.5 * u - 0.5 * v
        return np.stack([a, a + u, a + u + v, a + v])

    # ---- the twin (rect.glsl, function by function)
    @staticmethod
    def rect_polygon(x, p):
        """``(p, e, count)`` of the light seen from ``x`` (N, 3), as rect.glsl's ``rect_polygon``."""
        u, v = p.u, p.v
        a = (p.center - x) - 0.5 * u - 0.5 * v
        points = np.zeros((len(x), 10, 3), x.dtype)
        edges = np.zeros((len(x), 10, 3), x.dtype)
        b = a + u
        points[:, 0], points[:, 1], points[:, 2], points[:, 3] = a, b, b + v, a + v
        edges[:, :4] = np.stack(np.broadcast_arrays(u, v, -u, -v), axis=0)[None]
        count = np.where(_dot(x - p.center, np.cross(u, v)) > 0, 4, 0)
        return points, edges, count

    polygon_of = rect_polygon
    offset_uniform = "center"  # rect_polygon reads the centre only through center - x

    def sample(self, x, n, k, p):
        m = int(p.samples)
        a, b = k // m, k - (k // m) * m
        y = (p.center - x) + p.u * ((a + 0.5) / m - 0.5) + p.v * ((b + 0.5) / m - 0.5)
        valid, wi, d = safe_normalize(y)
        front = np.cross(p.u, p.v)
        area = np.linalg.norm(front)
        cos_l = -_dot(front, wi) / area
        with np.errstate(divide="ignore", invalid="ignore"):
            irradiance = p.radiance * (((cos_l * (area / (m * m))) / d) / d)[:, None]
        return valid & (k < m * m) & (cos_l > 0), wi, irradiance

    @classmethod
    def stability_cases(cls):
        up, tilted = (0.0, 0.0, 1.0), (np.sin(1.2), 0.0, np.cos(1.2))
        overhead = cls((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), 2.0)
        return extended_cases("rect", (
            ("overhead", overhead, up),
            ("straddling the horizon (normal tilted 69 deg)", overhead, tilted),
            ("touching the surface (its edge on the plane, 0.3 m away)", cls((0.0, 0.3, 0.25), (1.0, 0.0, 0.0),
                                                                          (0.0, 0.0, 0.5), 2.0), up),
            ("edge-on (the point in its plane)", cls((2.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 2.0), up),
            ("1e-4 m at 1 m (a point), Lambert", cls((0.0, 0.0, 1.0), (0.0, 1e-4, 0.0), (1e-4, 0.0, 0.0), 2.0e8),
             (0.5, 0.3, 1.0), Lambert(0.3)),
            ("behind (emitting away)", cls((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 2.0), up),
            ("q = 1", overhead, 1), ("q = 10", overhead, 10), ("q = 1000", overhead, 1000), ("q = 1e4", overhead, 10000),
            ("q = 1e4, the lobe on an edge", cls((0.5, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), 2.0), 10000)))

    def exact(self, x, n, p, integrand, clip=()):
        a = p.center - 0.5 * p.u - 0.5 * p.v  # the corners of the float32 uniforms, in float64
        return polygon_integral(x, n, np.stack([a, a + p.u, a + p.u + p.v, a + p.v]), p.radiance, integrand, clip=clip)


class PolygonLight(_Polygonal, ExtendedLight):
    """A one-sided uniform planar convex polygon light, emitting toward the side from which its vertices run
    counter-clockwise.

    At a point ``x`` with normal ``n``: ``E(n) = L integral (n.w)^+ dw`` over the polygon as seen from ``x``, exactly
    (Lambert's edge formula, clipped to the horizon); the lecture's Phong lobe ``integral max(r.w, 0)^q L [n.w > 0]
    dw`` exactly for integer ``q`` (Arvo's edge recurrences); every other term by the midpoint rule, ``E_k = L cos_l
    A_k / d_k^2`` toward each of its cells.  Its power is ``pi L A``.

    Parameters
    ----------
    vertices : (V, 3) array_like
        3 to 8 vertices [m], planar and convex, counter-clockwise seen from the side the light emits to.
    radiance : float or (3,) array_like
        ``L`` [W/(m^2 sr)].
    samples : int
        Sub-triangles per side of each fan triangle of the sampled method, 1 to 64 (default 4).
    """

    name = "polygon"
    loop_order = 5
    params = (RADIANCE, SAMPLES)
    uniforms = (Param("vertex", "vec3", low=-np.inf, unit="m", doc="the vertices, padded to 8"),
                Param("edge", "vec3", low=-np.inf, unit="m", doc="v_{i+1} - v_i, in float64, padded to 8"),
                Param("count", "scalar", low=3.0, high=8.0, doc="number of vertices"),
                Param("normal", "direction", low=-np.inf, doc="front normal: the side it emits to"),
                RADIANCE, SAMPLES)
    uniform_lengths = {"vertex": MAX_POLYGON_VERTICES, "edge": MAX_POLYGON_VERTICES}
    exact_uniforms = ("samples", "count")
    glsl = GlslFile("lights/polygon.glsl")
    uses = ("angle", "area")
    integrals = ("irradiance", "lobe")
    exact_integrals = ("irradiance", "lobe")

    def __init__(self, vertices, radiance, samples=4.0, method="auto"):
        object.__setattr__(self, "vertices", _convex_polygon(vertices))
        super().__init__(radiance, samples, method=method)

    @classmethod
    def example(cls, **overrides):
        """A regular pentagon of radius 0.4 m, 1 m above the origin, emitting down (clockwise seen from above)."""
        angles = -2.0 * np.pi * np.arange(5) / 5
        vertices = [(0.4 * np.cos(a), 0.4 * np.sin(a), 1.0) for a in angles]
        return cls(**({"vertices": vertices, "radiance": 0.5} | overrides))

    def parameter_values(self):
        return {"vertices": tuple(map(tuple, self.vertices))} | super().parameter_values()

    def normal(self):
        """The front normal (3,)."""
        v = np.asarray(self.vertices)
        normal = np.cross(v[1] - v[0], v[2] - v[0])
        return normal / np.linalg.norm(normal)

    def area(self):
        """Its area [m^2] (the fan's triangles)."""
        v = np.asarray(self.vertices)
        return float(sum(np.linalg.norm(np.cross(v[i] - v[0], v[i + 1] - v[0])) for i in range(1, len(v) - 1)) / 2)

    def power(self):
        """``pi L A`` [W] (3,)."""
        return np.pi * np.asarray(self.radiance) * self.area()

    def sample_count(self):
        return (len(self.vertices) - 2) * int(self.samples) ** 2

    def uniform_value(self, name):
        v = np.asarray(self.vertices)
        pad = np.zeros((MAX_POLYGON_VERTICES, 3))
        if name == "vertex":
            pad[:len(v)] = v
            pad[len(v):] = v[-1]
            return pad
        if name == "edge":
            pad[:len(v)] = np.roll(v, -1, axis=0) - v
            return pad
        if name == "count":
            return float(len(v))
        if name == "normal":
            return self.normal()
        return getattr(self, name)

    # ---- the twin (polygon.glsl, function by function)
    @staticmethod
    def polygon_polygon(x, p):
        """``(p, e, count)`` seen from ``x`` (N, 3), as polygon.glsl's ``polygon_polygon``."""
        count = int(p.count)
        points, edges, _ = polygon_arrays(p.vertex[:count], p.edge[:count], x, x.dtype)
        front = _dot(x - p.vertex[0], p.normal) > 0
        return points, edges, np.where(front, count, 0)

    polygon_of = polygon_polygon

    def sample(self, x, n, k, p):
        m = int(p.samples)
        t = 1 + k // (m * m)
        t1 = min(t, 6)
        a = p.vertex[0]
        y, area = area_triangle_sample(a - x, p.vertex[t1] - a, p.vertex[t1 + 1] - a, m, k - (t - 1) * m * m)
        valid, wi, d = safe_normalize(y)
        cos_l = -_dot(p.normal, wi)
        with np.errstate(divide="ignore", invalid="ignore"):
            irradiance = p.radiance * (((cos_l * area) / d) / d)[:, None]
        return valid & (t + 1 < int(p.count)) & (cos_l > 0), wi, irradiance

    @classmethod
    def stability_cases(cls):
        pentagon = [(np.cos(t), np.sin(t), 1.2) for t in -np.linspace(0, 2 * np.pi, 6)[:-1]]  # clockwise from above
        return extended_cases("polygon", (
            ("pentagon overhead", cls(pentagon, 2.0), (0.0, 0.0, 1.0)),
            ("pentagon straddling the horizon", cls(pentagon, 2.0), (np.sin(1.3), 0.0, np.cos(1.3))),
            ("q = 7", cls(pentagon, 2.0), 7)))

    def exact(self, x, n, p, integrand, clip=()):
        return polygon_integral(x, n, np.asarray(p.vertex[:int(p.count)], np.float64), p.radiance, integrand, clip=clip)


def _convex_polygon(vertices):
    """``vertices`` checked: (V, 3) finite float32-representable, 3 <= V <= 8, planar within 1e-6 of its size, convex
    and non-degenerate (tuple of tuples)."""
    v = _validate.real_array("vertices", vertices, "a (V, 3) array of 3 to 8 vertices")
    if v.ndim != 2 or v.shape[1] != 3 or not 3 <= len(v) <= MAX_POLYGON_VERTICES:
        raise ValueError(f"vertices must be a (V, 3) array with 3 to {MAX_POLYGON_VERTICES} vertices (got shape {v.shape})")
    if not np.all(np.isfinite(v)) or np.any(np.abs(v) > _validate.FLT_MAX):
        raise ValueError("vertices must be finite and representable in float32")
    size = float(np.max(np.linalg.norm(v - v.mean(axis=0), axis=1)))
    normal = sum(np.cross(v[i] - v[0], v[i + 1] - v[0]) for i in range(1, len(v) - 1))
    length = np.linalg.norm(normal)
    if not size > 0 or not length > 1e-12 * size * size:
        raise ValueError("vertices must span a polygon of non-zero area")
    normal = normal / length
    off = np.abs((v - v[0]) @ normal)
    if off.max() > 1e-6 * size:
        raise ValueError(f"vertices must be planar: vertex {int(off.argmax())} is {off.max():.3g} m off the plane of "
                         f"the others (tolerance {1e-6 * size:.3g} m)")
    turns = [np.dot(np.cross(v[(i + 1) % len(v)] - v[i], v[(i + 2) % len(v)] - v[(i + 1) % len(v)]), normal)
             for i in range(len(v))]
    if min(turns) <= 0:
        raise ValueError(f"vertices must form a convex polygon, counter-clockwise seen from the side it emits to: the "
                         f"turn at vertex {(int(np.argmin(turns)) + 1) % len(v)} is not to the left")
    return tuple(tuple(float(c) for c in row) for row in v)
