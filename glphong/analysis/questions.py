"""glphong.analysis: the lecture's four questions about a BRDF, answered by measurement.

Is it non-negative, energy-conserving, reciprocal, isotropic?  For any `glphong.materials.Material`
(built-in or user-defined), evaluated through its numpy twin in float64 (`glphong.testing.evaluate`
with ``twin=True``) or, on request, through its GLSL on the GPU (float32).  The normal is +z and the
tangent +x; ``f_r = response / (n.wi)``, with ``n.wi`` the z of the float32-rounded ``wi`` exactly as
`evaluate` forms it.

- `albedo`: the directional albedo ``rho(theta_i) = int f_r(wi, wo) cos(theta_o) d omega_o`` over the
  upper hemisphere, per channel;
- `properties`: one `BrdfProperties` record with ``non_negative``, ``min_value``, ``energy_conserving``,
  ``max_albedo``, ``reciprocal``, ``reciprocity_error``, ``isotropic``, ``isotropy_error`` (and the
  declared `glphong.materials.Properties`, the disagreements, the worst pairs, the quadrature error);
- `format_properties`: the record as text (``glphong brdf``).

The albedo quadrature
---------------------
The integrand ``g(wo) = f_r(wi, wo) cos(theta_o)`` may be a lobe of any width (Phong exponents up to
1e4 and beyond, Beckmann slopes down to 0.01) anywhere in the hemisphere, also clipped by the horizon.
The quadrature adapts to it:

1. the peak ``p`` of ``g``: the argmax over a coarse grid (32 x 64 plus the mirror, normal and
   retro-reflection directions), refined by shrinking local grids around it down to 1e-7 rad;
2. a frame ``(t, b, p)`` around the peak with ``t`` horizontal; in its polar coordinates
   ``(theta', phi')`` the hemisphere is exactly ``0 <= theta' <= theta_max(phi')``, where the ray from
   ``p`` at azimuth ``phi'`` meets the horizon (closed form): the horizon is a boundary of the domain,
   never a discontinuity inside it;
3. in ``u = 1 - cos(theta')`` (``d omega = du d phi'``) Gauss-Legendre on geometric panels
   ``[u_max 2^-(k+1), u_max 2^-k]`` down to ``u = 1e-14 u_max`` (every lobe width is resolved by some
   panel), the wide panels split to at most 1/8 in u;
4. in ``phi'`` Gauss-Legendre on panels graded geometrically toward ``phi' = 0, pi`` (where
   ``theta_max`` changes fastest when the peak is near the horizon, on the scale of ``p_z``).

Two resolutions (``nodes`` and ``nodes + 4`` Gauss points per panel) are computed; the finer is the
answer and their difference the stated error estimate ``quadrature_error``.  Measured against closed
forms (twin, tests/test_analysis.py): Lambert ``pi kd`` and Diffuse ``rho_d`` to 1.4e-13 at 0, 40 and
80 degrees; the normal-incidence specular albedo ``rho_s`` of NormalizedPhong to 8e-11 and of
NormalizedBlinnPhong to 4.3e-10 for q from 1 to 1e4 (estimates <= 1.1e-9); the lecture's Phong lobe
``ks 2 pi / (q + 2)`` at normal incidence to 4e-11 (q = 20) and 5e-14 (q = 1e4); Cook-Torrance
(m = 0.01, F = 1) 1 - 5e-10 at normal incidence (estimate 3e-9); NormalizedPhong q = 1e4 at 60 to 85
degrees matches ``rho_s cos(theta_i)`` (estimates <= 1.3e-9).  About 0.6 s per incident angle.

Known limits: a sharp lobe centred within about a degree of the horizon is resolved less well
(Cook-Torrance m = 0.01 at theta_i = 89 degrees: estimate 2e-3; at 85 degrees 1.1e-6): the stated
``quadrature_error`` says so.  A second sharp lobe far from the main peak, or an anisotropic lobe of
large aspect ratio, is resolved only as well as the outer panels allow (reported by the estimate,
not verified against closed forms).
"""
import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from glphong.evaluation import direction_sets, evaluate, float32_units

__all__ = ["f_r", "albedo", "properties", "format_properties", "BrdfProperties", "hemisphere_directions",
           "DEFAULT_THETA_I"]

#: incident angles [rad] of the white-furnace test in `properties`: cos(theta_i) from 1 to 1e-3
DEFAULT_THETA_I = np.arccos(np.concatenate([np.linspace(1.0, 0.1, 10), [0.05, 0.02, 1e-2, 3e-3, 1e-3]]))

_CHUNK = 250_000


# --------------------------------------------------------------------------- evaluation
def f_r(material, wi, wo, tangent=(1.0, 0.0, 0.0), gpu=False, backend="auto"):
    """The BRDF of ``material`` at direction pairs (normal +z): its response over ``n.wi``.

    Parameters
    ----------
    material : glphong.materials.Material
    wi, wo : (N, 3) array_like
        Directions toward the light and the viewer (normalised and rounded to float32, as
        `glphong.testing.evaluate` does).
    tangent : (3,) array_like
        The surface tangent, for anisotropic terms.
    gpu : bool
        The GLSL on the GPU (float32) instead of the float64 twin.
    backend : {'auto', 'egl', 'osmesa'}

    Returns
    -------
    (N, 3) float64 ndarray
        ``f_r`` [1/sr]; 0 where ``n.wi <= 0``.  Evaluated in chunks of 250000 pairs.
    """

    wi = np.asarray(wi, dtype=np.float64)
    wo = np.asarray(wo, dtype=np.float64)
    out = np.empty((len(wi), 3))
    for s in range(0, len(wi), _CHUNK):
        a, b = wi[s:s + _CHUNK], wo[s:s + _CHUNK]
        if gpu:
            r = evaluate(material, a, b, tangent=tangent, backend=backend).astype(np.float64)
        else:
            r = evaluate(material, a, b, tangent=tangent, twin=True)
        nz = float32_units(a)[:, 2]  # n.wi exactly as evaluate forms it
        with np.errstate(divide="ignore", invalid="ignore"):
            out[s:s + _CHUNK] = np.where((nz > 0)[:, None], r / np.where(nz > 0, nz, 1.0)[:, None], 0.0)
    return out


def _evaluator(material, gpu=False, backend="auto"):
    """``f(wi, wo, tangent) -> f_r``: `f_r` with the material and the evaluator fixed."""
    return lambda wi, wo, tangent=(1.0, 0.0, 0.0): f_r(material, wi, wo, tangent, gpu, backend)


# --------------------------------------------------------------------------- quadrature
def _gauss(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return (x + 1) / 2, w / 2  # on [0, 1]


def _u_fractions(nodes):
    """Nodes and weights of [0, 1] (fractions of u_max): geometric panels toward 0, wide ones split."""
    edges = [0.0] + [2.0 ** -k for k in range(46, -1, -1)]  # 2^-46 ~ 1.4e-14
    fine = []
    for a, b in zip(edges[:-1], edges[1:]):
        pieces = max(1, int(math.ceil((b - a) / 0.0625)))
        fine += [a + (b - a) * j / pieces for j in range(pieces)]
    fine.append(1.0)
    x, w = _gauss(nodes)
    a, b = np.array(fine[:-1]), np.array(fine[1:])
    return (a[:, None] + (b - a)[:, None] * x).ravel(), ((b - a)[:, None] * w).ravel()


def _phi_nodes(nodes, scale):
    """Nodes and weights on [0, 2 pi): panels graded geometrically toward 0, pi (and 2 pi) to ``scale``."""
    half = np.pi / 2
    levels = max(0, int(math.ceil(math.log2(half / max(scale, 1e-9)))))
    # panels of [0, pi/2] toward 0
    edges = [0.0] + [half * 2.0 ** -k for k in range(levels, -1, -1)]
    refined = []
    for a, b in zip(edges[:-1], edges[1:]):
        pieces = max(1, int(math.ceil((b - a) / (np.pi / 8))))
        refined += [a + (b - a) * j / pieces for j in range(pieces)]
    refined.append(half)
    e = np.array(refined)
    x, w = _gauss(nodes)
    a, b = e[:-1], e[1:]
    t = (a[:, None] + (b - a)[:, None] * x).ravel()
    wt = ((b - a)[:, None] * w).ravel()
    # [0, pi/2] toward 0, [pi/2, pi] toward pi, [pi, 3pi/2] toward pi, [3pi/2, 2pi] toward 2pi
    phi = np.concatenate([t, np.pi - t, np.pi + t, 2 * np.pi - t])
    return phi, np.tile(wt, 4)


def _peak_frame(p):
    """``(t, b)`` with ``t`` horizontal (t_z = 0) and ``b`` toward +z, ``(t, b, p)`` orthonormal."""
    horizontal = np.array([-p[1], p[0], 0.0])
    length = np.linalg.norm(horizontal)
    t = np.array([1.0, 0.0, 0.0]) if length < 1e-300 else horizontal / length
    b = np.cross(p, t)
    if b[2] < 0:
        t, b = -t, -b
    return t, b


def _sphere_dirs(p, t, b, theta, phi):
    s = np.sin(theta)[..., None]
    return np.cos(theta)[..., None] * p + s * (np.cos(phi)[..., None] * t + np.sin(phi)[..., None] * b)


def _find_peak(f, wi, coarse=(32, 64)):
    """The direction (unit, z > 0) maximising ``sum_channels f_r(wi, wo) cos(theta_o)``."""
    nz, nphi = coarse
    z = (np.arange(nz) + 0.5) / nz
    phi = (np.arange(nphi) + 0.5) * 2 * np.pi / nphi
    zz, pp = np.meshgrid(z, phi, indexing="ij")
    s = np.sqrt(1 - zz ** 2)
    grid = np.stack([s * np.cos(pp), s * np.sin(pp), zz], -1).reshape(-1, 3)
    mirror = wi * np.array([-1.0, -1.0, 1.0])
    extra = np.array([mirror, [0.0, 0.0, 1.0], wi])
    extra[:, 2] = np.maximum(extra[:, 2], 1e-9)
    cand = np.concatenate([grid, extra / np.linalg.norm(extra, axis=1, keepdims=True)])

    def score(d):
        with np.errstate(invalid="ignore"):
            v = np.sum(f(np.broadcast_to(wi, d.shape), d), axis=1) * d[:, 2]
        return np.where(np.isfinite(v), v, -np.inf)

    v = score(cand)
    best = cand[int(np.argmax(v))]
    best_value = float(np.max(v))
    radius = 0.1
    g = np.linspace(-1, 1, 7)
    gx, gy = np.meshgrid(g, g)
    gx, gy = gx.ravel(), gy.ravel()
    while radius > 1e-7:
        t, b = _peak_frame(best)
        d = best + radius * (gx[:, None] * t + gy[:, None] * b)
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
        d = d[d[:, 2] > 0]
        if len(d):
            vv = score(d)
            k = int(np.argmax(vv))
            if vv[k] > best_value:
                best, best_value = d[k], float(vv[k])
                continue  # move, keep the radius
        radius /= 3
    return best


def _albedo_one(f, theta_i, nodes=8):
    """(rho (3,), error estimate (3,), peak (3,)) at one incident angle."""
    wi = np.array([math.sin(theta_i), 0.0, math.cos(theta_i)])
    p = _find_peak(f, wi)
    t, b = _peak_frame(p)
    results = []
    for n in (nodes, nodes + 4):
        phi, wphi = _phi_nodes(n, scale=min(1.0, 1e-3 * p[2]))
        # the horizon: z(theta') = cos theta' p_z + sin theta' a(phi'), a = sin(phi') b_z (t_z = 0)
        a = np.cos(phi) * t[2] + np.sin(phi) * b[2]
        theta_max = np.arctan2(a, p[2]) + np.pi / 2
        u_max = 1 - np.cos(theta_max)
        fu, wu = _u_fractions(n)
        u = u_max[:, None] * fu[None, :]
        w = (wphi * u_max)[:, None] * wu[None, :]
        theta = np.arccos(np.clip(1 - u, -1.0, 1.0))
        wo = _sphere_dirs(p, t, b, theta, np.broadcast_to(phi[:, None], theta.shape)).reshape(-1, 3)
        cos_o = np.maximum(wo[:, 2], 0.0)
        wo[:, 2] = np.maximum(wo[:, 2], 1e-300)
        value = f(np.broadcast_to(wi, wo.shape), wo) * cos_o[:, None]
        value = np.where(cos_o[:, None] > 0, value, 0.0)
        results.append(np.sum(value * w.reshape(-1, 1), axis=0))
    return results[1], np.abs(results[1] - results[0]), p


def albedo(material, theta_i, gpu=False, backend="auto", nodes=8, return_error=False):
    """The directional albedo ``rho(theta_i) = int f_r(wi, wo) cos(theta_o) d omega_o`` [dimensionless].

    ``wi = (sin theta_i, 0, cos theta_i)``, normal +z, tangent +x; the integral over the upper hemisphere
    of ``wo`` by the peak-centred adaptive Gauss-Legendre rule of the module docstring (about 1e5
    evaluations per angle and resolution).

    Parameters
    ----------
    material : glphong.materials.Material
    theta_i : float or array_like
        Incident angles [rad] from the normal, in [0, pi/2).
    gpu : bool
        Evaluate the material's GLSL on the GPU (float32) instead of the float64 twin.
    backend : {'auto', 'egl', 'osmesa'}
    nodes : int
        Gauss points per panel of the coarser resolution (the answer uses ``nodes + 4``).
    return_error : bool
        Also return the error estimate (|difference of the two resolutions|), same shape.

    Returns
    -------
    ndarray, float64, shape ``np.shape(theta_i) + (3,)``
        Measured accuracy against closed forms (twin): better than 1e-9 absolute for the lobes of the
        tests (q up to 1e4, Beckmann m = 0.01, lobes not within a few degrees of the horizon), 1.4e-13 for the diffuse
        models; see the module docstring for the limits near the horizon.
    """
    theta = np.asarray(theta_i, dtype=np.float64)
    if np.any(~np.isfinite(theta)) or np.any(theta < 0) or np.any(theta >= np.pi / 2):
        raise ValueError("theta_i must be in [0, pi/2) rad")
    f = _evaluator(material, gpu, backend)
    flat = theta.ravel()
    rho = np.empty((len(flat), 3))
    err = np.empty((len(flat), 3))
    for k, th in enumerate(flat):
        rho[k], err[k], _ = _albedo_one(f, float(th), nodes)
    rho = rho.reshape(theta.shape + (3,))
    err = err.reshape(theta.shape + (3,))
    return (rho, err) if return_error else rho


# --------------------------------------------------------------------------- direction pairs
def hemisphere_directions(count):
    """A Fibonacci set of ``count`` unit directions over the upper hemisphere (z in (0, 1))."""
    k = np.arange(count) + 0.5
    z = 1 - k / count
    phi = k * np.pi * (3 - np.sqrt(5))
    s = np.sqrt(1 - z ** 2)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def _pairs(count, seed=0):
    d = hemisphere_directions(count)
    i, j = np.meshgrid(np.arange(count), np.arange(count), indexing="ij")
    wi, wo = d[i.ravel()], d[j.ravel()]

    ewi, ewo, _ = direction_sets(n=500, seed=seed)
    up = (ewi[:, 2] > 0) & (ewo[:, 2] > 0)
    return np.concatenate([wi, ewi[up]]), np.concatenate([wo, ewo[up]])


# --------------------------------------------------------------------------- the record
@dataclass
class BrdfProperties:
    """The measured answers for one material (`properties`); the first eight fields are the contract."""

    non_negative: bool
    min_value: float
    energy_conserving: bool
    max_albedo: float
    reciprocal: bool
    reciprocity_error: float
    isotropic: bool
    isotropy_error: float
    material: str = ""
    evaluated_by: str = "twin"
    min_at: tuple = ()             # (wi, wo) of the minimum of f_r
    max_value: float = 0.0         # the largest f_r over the pairs [1/sr]
    max_albedo_theta_i: float = 0.0  # where the albedo is largest [rad]
    quadrature_error: float = 0.0  # the largest error estimate of the albedos
    theta_i: list = field(default_factory=list)
    albedo: list = field(default_factory=list)  # (len(theta_i), 3)
    reciprocity_worst: tuple = ()  # (wi, wo)
    isotropy_worst: tuple = ()     # (wi, wo, rotation [rad], 'tangent' or 'directions')
    pairs: int = 0
    non_finite: int = 0
    tolerance: float = 0.0
    declared: dict = field(default_factory=dict)
    disagreements: list = field(default_factory=list)

    def to_dict(self):
        return _plain(asdict(self))

    def to_json(self):
        return json.dumps(self.to_dict(), indent=2)


def _plain(x):
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, (np.floating, float)):
        v = float(x)
        return v if math.isfinite(v) else str(v)
    if isinstance(x, (np.bool_,)):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    return x


def properties(material, gpu=False, backend="auto", directions=300, theta_i=None, nodes=8, tolerance=None, seed=0):
    """Measure whether a material's BRDF is non-negative, energy-conserving, reciprocal and isotropic.

    Parameters
    ----------
    material : glphong.materials.Material
    gpu : bool
        Evaluate on the GPU (`glphong.testing.evaluate` with ``backend``; float32) instead of the twin.
    backend : {'auto', 'egl', 'osmesa'}
    directions : int
        Fibonacci directions per side: ``directions**2`` pairs (wi, wo) over the upper hemispheres, plus
        the upper-hemisphere edge pairs of `glphong.testing.direction_sets`.
    theta_i : array_like, optional
        Incident angles [rad] of the albedo (default `DEFAULT_THETA_I`, cos theta_i from 1 to 1e-3).
    nodes : int
        As in `albedo`.
    tolerance : float, optional
        Relative tolerance of the reciprocity, isotropy and non-negativity verdicts (default 1e-9 for the
        twin, 1e-2 for the GPU's float32).
    seed : int

    Returns
    -------
    BrdfProperties
        Non-negativity: ``min_value = min f_r`` over the pairs (>= ``-tolerance max f_r`` counts as
        non-negative, max f_r over the pairs with both cosines at least 1e-3).  Energy: ``max_albedo`` over ``theta_i``, conserving when ``<= 1 +
        quadrature_error`` (floored at 1e-9).  Reciprocity: ``max |f_r(wi, wo) - f_r(wo, wi)| / max f_r``
        over pairs with both cosines at least 1e-3 (where ``f_r = response / (n.wi)`` is well defined; max
        f_r over the same pairs).
        Isotropy: the largest ``|f_r(R wi, R wo) - f_r(wi, wo)| / max f_r``, with R rotations about n by
        0.3, 1.1, 2.5 and 4.0 rad applied to the tangent frame (the inverse rotation: exact in float64
        for a model that reads only the frame) and by 90, 180 and 270 degrees applied to the
        directions (exact in float32, for a model that reads world axes).
    """

    tol = tolerance if tolerance is not None else (1e-2 if gpu else 1e-9)
    f = _evaluator(material, gpu, backend)
    wi, wo = _pairs(directions, seed)
    wi, wo = float32_units(wi), float32_units(wo)  # exactly what evaluate sees: swaps and 90-degree turns stay exact
    value = f(wi, wo)
    finite = np.isfinite(value)
    non_finite = int(np.count_nonzero(~finite.all(axis=1)))
    v = np.where(finite, value, np.nan)
    max_value = float(np.nanmax(np.abs(v))) if np.any(finite) else float("nan")
    scale = max_value if max_value > 0 else 1.0
    k = int(np.nanargmin(np.nanmin(v, axis=1)))
    min_value = float(np.nanmin(v[k]))

    # reciprocity
    ok = (wi[:, 2] >= 1e-3) & (wo[:, 2] >= 1e-3)
    # relative to the largest f_r where both cosines are at least 1e-3 (the lecture's Phong is ks/(n.wi),
    # Ward's 1/sqrt((n.l)(n.v)) at n.wi = 1e-30: that pair is left out of the comparison, so it must not set its scale either)
    ok_max = np.nanmax(np.abs(v[ok])) if np.any(ok) else 0.0
    scale = float(ok_max) if ok_max > 0 else 1.0
    swapped = f(wo[ok], wi[ok])
    diff = np.abs(swapped - v[ok])
    diff = np.where(np.isfinite(diff), diff, 0.0).max(axis=1)
    r = int(np.argmax(diff))
    reciprocity_error = float(diff[r] / scale)
    reciprocity_worst = (wi[ok][r], wo[ok][r])

    # isotropy
    worst = (0.0, None)
    for angle in (0.3, 1.1, 2.5, 4.0):  # rotating wi, wo by +angle = rotating the frame by -angle
        turned = f(wi[ok], wo[ok], tangent=(math.cos(angle), -math.sin(angle), 0.0))
        d = np.abs(turned - v[ok])
        d = np.where(np.isfinite(d), d, 0.0).max(axis=1)
        j = int(np.argmax(d))
        if d[j] / scale > worst[0] or worst[1] is None:
            worst = (float(d[j] / scale), (wi[ok][j], wo[ok][j], angle, "tangent"))
    for quarter in (1, 2, 3):
        def rot(x, q=quarter):
            y = x.copy()
            for _ in range(q):
                y = np.stack([-y[:, 1], y[:, 0], y[:, 2]], axis=1)
            return y

        turned = f(rot(wi[ok]), rot(wo[ok]))
        d = np.abs(turned - v[ok])
        d = np.where(np.isfinite(d), d, 0.0).max(axis=1)
        j = int(np.argmax(d))
        if d[j] / scale > worst[0]:
            worst = (float(d[j] / scale), (wi[ok][j], wo[ok][j], quarter * np.pi / 2, "directions"))

    # energy
    thetas = np.asarray(DEFAULT_THETA_I if theta_i is None else theta_i, dtype=np.float64).ravel()
    rho = np.empty((len(thetas), 3))
    err = np.empty((len(thetas), 3))
    for i, th in enumerate(thetas):
        rho[i], err[i], _ = _albedo_one(f, float(th), nodes)
    a = int(np.argmax(rho.max(axis=1)))
    max_albedo = float(rho[a].max())
    quadrature_error = float(np.max(err))

    record = BrdfProperties(
        non_negative=bool(min_value >= -tol * scale), min_value=min_value,
        energy_conserving=bool(max_albedo <= 1 + max(quadrature_error, 1e-9)), max_albedo=max_albedo,
        reciprocal=bool(reciprocity_error <= tol), reciprocity_error=reciprocity_error,
        isotropic=bool(worst[0] <= tol), isotropy_error=worst[0],
        material=repr(material), evaluated_by=f"gpu ({backend})" if gpu else "twin (float64)",
        min_at=(wi[k], wo[k]), max_value=max_value, max_albedo_theta_i=float(thetas[a]),
        quadrature_error=quadrature_error, theta_i=thetas, albedo=rho, reciprocity_worst=reciprocity_worst,
        isotropy_worst=worst[1] or (), pairs=len(wi), non_finite=non_finite, tolerance=tol)
    declared = getattr(material, "properties", None)
    if declared is not None:
        record.declared = {k: getattr(declared, k) for k in
                           ("non_negative", "energy_conserving", "reciprocal", "isotropic", "condition")}
        for name in ("non_negative", "energy_conserving", "reciprocal", "isotropic"):
            said = getattr(declared, name)
            if said is not None and bool(said) != getattr(record, name):
                record.disagreements.append(name)
    return record


def format_properties(record):
    """The record as a readable block of text (what ``glphong brdf`` prints)."""
    def yes(b):
        return "yes" if b else "no"

    def vec(x):
        return "(" + ", ".join(f"{c:.4g}" for c in np.asarray(x, dtype=float)) + ")"

    d = record.declared
    lines = [f"{record.material}  [{record.evaluated_by}, {record.pairs} direction pairs]"]

    def row(name, answer, text):
        said = d.get(name)
        note = "" if said is None else f"  (declared {yes(said)}{'; DISAGREES' if name in record.disagreements else ''})"
        lines.append(f"  {name.replace('_', '-') + ':':19s} {yes(answer):3s}  {text}{note}")

    where = f" at wi={vec(record.min_at[0])}, wo={vec(record.min_at[1])}" if len(record.min_at) else ""
    row("non_negative", record.non_negative, f"min f_r = {record.min_value:.6g} 1/sr{where}")
    row("energy_conserving", record.energy_conserving,
        f"max albedo = {record.max_albedo:.9g} at theta_i = {math.degrees(record.max_albedo_theta_i):.3f} deg "
        f"(quadrature error <= {record.quadrature_error:.2g})")
    row("reciprocal", record.reciprocal, f"max |f(wi,wo) - f(wo,wi)| / max f = {record.reciprocity_error:.3g}")
    row("isotropic", record.isotropic, f"max change under rotation about n / max f = {record.isotropy_error:.3g}")
    if d.get("condition"):
        lines.append(f"  declared condition: {d['condition']}")
    if record.non_finite:
        lines.append(f"  note: {record.non_finite} pairs gave a non-finite f_r (left out)")
    return "\n".join(lines)
