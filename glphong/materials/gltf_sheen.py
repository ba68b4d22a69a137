"""KHR_materials_sheen on `GltfPBR` (docs/gltf_extensions.md; GLSL: ``glsl/materials/gltf_pbr.glsl`` under
``GLTF_PBR_SHEEN``): the twin's functions, the specification's formulas in mpmath for the stability suite, and the
stability cases.  With ``alpha_g = sheen_roughness^2``, ``sin2h = 1 - (n.h)^2``::

    D_s = (2 + 1/alpha_g) sin2h^(1/(2 alpha_g)) / (2 pi)                                   Charlie
    V_s = 1 / ((1 + lambda(n.v) + lambda(n.l)) 4 (n.v)(n.l))                               the specification's fit
    f_r' = sheen_color D_s V_s + f_r max(min(1 - max3(sheen_color) E(n.v), 1 - max3(sheen_color) E(n.l)), 0)

``E(x, r)``: the sheen lobe's directional albedo with ``sheen_color = 1``, integrated in float64 from ``D_s V_s`` by
benchmarks/gltf_sheen_albedo.py, shipped as `glphong.materials.gltf_sheen_table.SHEEN_ALBEDO` (33 values of ``n.v =
(i/32)^2`` by 17 of ``r = j/16``, float32) and looked up bilinearly in ``sqrt(n.v)`` and ``r``.  E exceeds 1 at grazing
view for small sheen roughness (3.24 at ``n.v = 1/1024``, ``r = 1/16``), where the specification's scaling is negative:
glphong clamps it at 0 (the base reflects nothing there; docs/gltf_extensions.md gives the figures).  Roughness 0: D_s
is a delta at ``n.h = 0``, which no pair of directions above the surface meets, so the sheen reflects nothing and E is
0 (the table's row 0).  Below ``n.v = 1/1024`` the table holds E at its value there (E grows without bound as ``n.v ->
0``).
"""
import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit
from glphong.definitions.params import Param
from glphong.materials.gltf_sheen_table import SHEEN_ALBEDO
from glphong.twin.band import FLT_MAX
from glphong.twin.functions import microfacet_geometry

__all__ = ["SHEEN_PARAMS", "gltf_sheen_distribution", "gltf_sheen_l", "gltf_sheen_lambda", "gltf_sheen_albedo",
           "gltf_sheen_scaling", "gltf_sheen_mix", "gltf_sheen_oracle", "sheen_cases"]

_SHEEN_COLOR = Param("sheen_color", "rgb", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                     doc="KHR_materials_sheen sheenColorFactor (times sheenColorTexture, sRGB): the sheen's colour")
_SHEEN_ROUGHNESS = Param("sheen_roughness", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                         doc="KHR_materials_sheen sheenRoughnessFactor (times sheenRoughnessTexture.a): alpha_g = "
                             "sheen_roughness^2")
#: the sheen's parameters, appended to `GltfPBR`'s
SHEEN_PARAMS = (_SHEEN_COLOR, _SHEEN_ROUGHNESS)
_TABLE = np.asarray(SHEEN_ALBEDO, np.float32)  # (17, 33)
#: the specification's fit of lambda: (a, b, c, d, e) at (1 - alpha_g)^2 = 0 and 1
_FIT = ((21.5473, 25.3245), (3.82987, 3.32435), (0.19823, 0.16801), (-1.97760, -1.27393), (-4.32054, -4.85967))


def _mix(a, b, t):
    """GLSL's ``mix``: ``a (1 - t) + b t``."""
    return a * (t.dtype.type(1) - t) + b * t


def gltf_sheen_distribution(tan2, alpha_g):
    """Charlie ``D = (2 + 1/alpha_g) sin2h^(1/(2 alpha_g)) / (2 pi)``, ``sin2h = tan2/(1 + tan2)``; 0 for ``alpha_g =
    0`` (gltf_pbr.glsl).  tan2 (...), alpha_g (...) or () -> (...) [1/sr]."""
    tan2 = np.asarray(tan2)
    dtype = tan2.dtype
    alpha_g = np.asarray(alpha_g).astype(dtype)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        sin2h = (tan2 / (dtype.type(1) + tan2)).astype(dtype)
        inv_r = np.where(alpha_g > 0, dtype.type(1) / np.where(alpha_g > 0, alpha_g, dtype.type(1)), dtype.type(0))
        d = (dtype.type(2) + inv_r) * np.power(sin2h, dtype.type(0.5) * inv_r) * dtype.type(0.5 / np.pi)
        return np.where(alpha_g > 0, d, dtype.type(0)).astype(dtype)


def gltf_sheen_l(x, alpha_g):
    """The specification's fit ``l(x) = a/(1 + b x^c) + d x + e``, ``a..e = mix(., ., (1 - alpha_g)^2)``."""
    x = np.asarray(x)
    dtype = x.dtype
    t = (dtype.type(1) - np.asarray(alpha_g).astype(dtype)) ** 2
    a, b, c, d, e = (_mix(dtype.type(p), dtype.type(q), t.astype(dtype)) for p, q in _FIT)
    with np.errstate(divide="ignore", under="ignore"):
        return (a / (dtype.type(1) + b * np.power(x, c)) + d * x + e).astype(dtype)


def gltf_sheen_lambda(cos_theta, alpha_g):
    """``exp(l(|cos|))`` below 0.5, ``exp(2 l(0.5) - l(1 - |cos|))`` from 0.5 (gltf_pbr.glsl)."""
    x = np.abs(np.asarray(cos_theta))
    dtype = x.dtype
    with np.errstate(over="ignore"):
        return np.where(x < dtype.type(0.5), np.exp(gltf_sheen_l(x, alpha_g)),
                        np.exp(dtype.type(2) * gltf_sheen_l(np.full_like(x, 0.5), alpha_g)
                               - gltf_sheen_l(dtype.type(1) - x, alpha_g))).astype(dtype)


def gltf_sheen_albedo(cos_theta, sheen_roughness):
    """``E(cos, r)``: bilinear in the table at ``u = 32 sqrt(cos)``, ``w = 16 r`` (gltf_pbr.glsl's order);
    (...) -> (...)."""
    cos_theta = np.asarray(cos_theta)
    dtype = cos_theta.dtype
    u = (np.sqrt(np.clip(cos_theta, 0, 1)) * dtype.type(32)).astype(dtype)
    w = (np.clip(np.asarray(sheen_roughness).astype(dtype), 0, 1) * dtype.type(16)).astype(dtype)
    u, w = np.broadcast_arrays(u, w)
    i, j = np.minimum(u.astype(int), 31), np.minimum(w.astype(int), 15)
    s, t = u - i.astype(dtype), w - j.astype(dtype)
    table = _TABLE.astype(dtype)
    low = _mix(table[j, i], table[j, i + 1], s)
    high = _mix(table[j + 1, i], table[j + 1, i + 1], s)
    return _mix(low, high, t).astype(dtype)


def gltf_sheen_scaling(n_dot_v, n_dot_l, sheen_color, sheen_roughness):
    """The specification's albedo scaling ``max(min(1 - m E(n.v), 1 - m E(n.l)), 0)``, ``m = max3(sheen_color)``, E
    `gltf_sheen_albedo` (gltf_pbr.glsl's ``gltf_sheen_scaling``: the base's under the sheen, and
    transmission_thin.glsl's over the light let through).

    Parameters
    ----------
    n_dot_v, n_dot_l : (N,) ndarray
        The view's and the light's cosines (float32 or float64: the arithmetic follows ``n_dot_v``).
    sheen_color : (N, 3) or (3,) ndarray
    sheen_roughness : (N,) ndarray or float

    Returns
    -------
    (N,) ndarray, dimensionless, in [0, 1]
    """
    n_dot_v = np.asarray(n_dot_v)
    dtype = n_dot_v.dtype if n_dot_v.dtype.kind == "f" else np.dtype(np.float64)
    n_dot_v, n_dot_l = n_dot_v.astype(dtype), np.asarray(n_dot_l).astype(dtype)
    r = np.asarray(sheen_roughness).astype(dtype)
    sc_max = np.max(np.broadcast_to(np.asarray(sheen_color).astype(dtype), n_dot_v.shape + (3,)), axis=-1)
    one = dtype.type(1)
    return np.maximum(np.minimum(one - sc_max * gltf_sheen_albedo(n_dot_v, r),
                                 one - sc_max * gltf_sheen_albedo(n_dot_l, r)), dtype.type(0)).astype(dtype)


def gltf_sheen_mix(value, f, wi, wo, n_dot_l, p):
    """KHR_materials_sheen on `GltfPBR`'s twin: ``value scaling + sheen_color D V (n.l)``, ``scaling =
    gltf_sheen_scaling(n.v, n.l)`` (gltf_pbr.glsl's order); value (N, 3) -> (N, 3)."""
    dtype = np.asarray(value).dtype
    _, n_dot_v, _, _, tan2 = microfacet_geometry(f.n, wi, wo, n_dot_l)
    n_dot_l, n_dot_v, tan2 = (np.asarray(a).astype(dtype) for a in (n_dot_l, n_dot_v, tan2))
    r = np.asarray(p.sheen_roughness).astype(dtype)
    alpha_g = (r * r).astype(dtype)
    sc = np.asarray(p.sheen_color, dtype)
    one = dtype.type(1)
    scaling = gltf_sheen_scaling(n_dot_v, n_dot_l, sc, r)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore", under="ignore"):
        v_cos = (one / ((one + gltf_sheen_lambda(n_dot_v, alpha_g) + gltf_sheen_lambda(n_dot_l, alpha_g))
                        * (dtype.type(4) * n_dot_v))).astype(dtype)
        sheen = np.minimum(gltf_sheen_distribution(tan2, alpha_g) * v_cos, dtype.type(FLT_MAX)).astype(dtype)
        return (value * scaling[..., None] + sc * sheen[..., None]).astype(dtype)


def gltf_sheen_oracle(out, p, n_dot_l, n_dot_v, n_dot_h):
    """The sheen over the base BRDF ``out`` (3 mpmath numbers [1/sr]) in mpmath from the specification's text,
    with E from the shipped table (mpmath would take minutes to integrate it; the table is tested against fresh
    integrals in tests/materials/test_gltf_sheen.py) and the scaling clamped at 0; a list of 3 mpmath numbers."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    r = mpmath.mpf(float(p.sheen_roughness))
    alpha = r * r
    if alpha == 0:
        d = mpmath.mpf(0)
    else:
        d = (2 + 1 / alpha) * (1 - n_dot_h ** 2) ** (1 / (2 * alpha)) / (2 * mpmath.pi)

    def lam(x):
        t = (1 - alpha) ** 2

        def l_fit(y):
            a, b, c, dd, e = (p0 + (q0 - p0) * t for p0, q0 in _FIT)
            return a / (1 + b * y ** c) + dd * y + e
        return mpmath.exp(l_fit(x)) if x < 0.5 else mpmath.exp(2 * l_fit(mpmath.mpf(0.5)) - l_fit(1 - x))

    sheen = d / ((1 + lam(n_dot_v) + lam(n_dot_l)) * 4 * n_dot_v * n_dot_l)
    colour = [mpmath.mpf(float(c)) for c in np.broadcast_to(np.asarray(p.sheen_color, np.float64), 3)]
    m = max(colour)
    e_v, e_l = (float(gltf_sheen_albedo(np.float64(x), float(p.sheen_roughness))) for x in (n_dot_v, n_dot_l))
    scaling = max(min(1 - m * e_v, 1 - m * e_l), 0)
    return [o * scaling + c * sheen for o, c in zip(out, colour)]


def sheen_cases(cls):
    """Stability cases of the sheen on `GltfPBR` ``cls``: roughness 0, 1e-2, 1/16, 0.5 and 1 at normal and oblique
    view; grazing view (E > 1 for small roughness: the scaling clamped at 0) and grazing light."""
    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    cases = []
    for roughness in (0.0, 1e-2, 1 / 16, 0.5, 1.0):
        for theta_h in (0.0, 0.6):
            cases.append(Case(f"gltf_pbr sheen roughness={roughness:g} theta_h={theta_h:g}", "gltf sheen",
                              cls((0.8, 0.5, 0.2), 0.0, 0.5, sheen_color=(1.0, 0.6, 0.3), sheen_roughness=roughness),
                              eye=_mirror_eye(30.0, 2 * theta_h), lights=(("point", _unit(30.0), e_one),)))
    for roughness in (0.05, 0.5):
        for nv in (1e-3, 1e-8, 1e-20):
            cases.append(Case(f"gltf_pbr sheen grazing view n.v={nv:g} roughness={roughness:g}", "gltf sheen",
                              cls(0.5, 0.3, 0.4, sheen_color=0.9, sheen_roughness=roughness, clearcoat=0.5,
                                  clearcoat_roughness=0.2),
                              eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv), lights=(("point", _unit(40.0), e_one),),
                              note="E(n.v) max3(sheen_color) > 1 for the small roughness: the base scaled by 0"))
    cases.append(Case("gltf_pbr sheen grazing light", "gltf sheen",
                      cls(0.5, 0.0, 0.5, sheen_color=1.0, sheen_roughness=0.3),
                      eye=_mirror_eye(30.0, 0.2), lights=(("point", _unit(89.99), e_one),)))
    return cases
