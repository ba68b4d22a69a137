"""The numpy twin of glphong's GLSL library chunks (docs/design.md sections 1 and 3).

Every function of the library chunks common, lights, lobe, fresnel and angle has its twin here with the
same name, the same argument order and the same formulation; only the arithmetic's dtype differs
(float64 for the reference, float32 to study the GPU's formulation on the CPU).  Conventions:

- vectors are arrays of shape ``(..., 3)``, scalars per point of shape ``(...)``;
- a GLSL function with ``out`` parameters returns ``(return value, *outs)``.

A material model's twin (its ``response``) is written with these; the image-level twin, which shades a
whole G-buffer, is `glphong.checks.reference`.
"""
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ShadingFrame", "safe_normalize", "plain_normalize", "frame_from_tangent", "shading_frame", "point_irradiance", "range_window", "perpendiculars", "log_one_minus_series", "log_one_minus",
    "lobe_from_delta", "phong_delta", "phong_lobe", "BLINN_HALF_FLOOR", "blinn_delta", "blinn_lobe", "half_cosine",
    "fresnel_schlick", "fresnel_dielectric", "atan2_first_quadrant", "microfacet_geometry", "microfacet_ggx", "light_term", "FLT_MAX",
    "FRAME_PARALLEL_LIMIT", "surface_normal",
]


@dataclass(frozen=True)
class ShadingFrame:
    """The twin's ``ShadingFrame`` (common.glsl): the local frame at each shading point.

    Attributes
    ----------
    n : (N, 3) ndarray
        Unit normal (flipped toward the viewer on back faces when two-sided).
    t, b : (N, 3) ndarray or None
        Unit tangent and bitangent, ``(t, b, n)`` right-handed up to the mesh's handedness sign;
        None unless a term needs ``'tangent'``.
    uv : (N, 2) ndarray or None
        Texture coordinates; None unless a term needs ``'uv'`` or a parameter is textured.
    inputs : dict of str to (N, 3) ndarray or None
        The twin's per-fragment values of surface inputs by uniform name (``u_<model>_<param>``: in GLSL
        the globals `material_inputs` sets); None where no parameter varies.
    input_bounds : dict of str to ((N, 3), (N, 3)) or None
        Their intervals for the tolerance band (`glphong.checks.tolerances.input_bounds`).
    visibility : tuple or None
        Per light of the program, in loop order: None (the light casts no shadows) or ``(exact, low, high)``,
        each (N,), its ray-cast visibility and the interval a shadow map may give (`glphong.checks.shadows`).
    unperturbed : ShadingFrame or None
        The frame before the material's normal map (normal_map.glsl's ``unperturbed_frame``: `shading_frame` of the
        interpolated normal), where it perturbed ``n`` and a term needs ``'unperturbed'``; None otherwise (then
        this frame is the unperturbed one).
    """

    n: np.ndarray
    t: np.ndarray = None
    b: np.ndarray = None
    uv: np.ndarray = None
    inputs: dict = None
    input_bounds: dict = None
    visibility: tuple = None
    unperturbed: "ShadingFrame" = None

    def select(self, mask):
        """The frame at the points where ``mask`` is true."""
        pick = lambda a: None if a is None else a[mask]  # noqa: E731
        inputs = None if self.inputs is None else {k: v[mask] for k, v in self.inputs.items()}
        bounds = None if self.input_bounds is None else \
            {k: (lo[mask], hi[mask]) for k, (lo, hi) in self.input_bounds.items()}
        visibility = None if self.visibility is None else \
            tuple(None if v is None else tuple(a[mask] for a in v) for v in self.visibility)
        unperturbed = None if self.unperturbed is None else self.unperturbed.select(mask)
        return ShadingFrame(self.n[mask], pick(self.t), pick(self.b), pick(self.uv), inputs, bounds, visibility,
                            unperturbed)


#: common.glsl FLT_MAX: vectors with a larger (or NaN) component do not normalise
FLT_MAX = float(np.finfo(np.float32).max)
#: common.glsl FRAME_PARALLEL_LIMIT (2^-10): a tangent whose part across n is at most this times its
#: part along n counts as parallel to n in `frame_from_tangent`
FRAME_PARALLEL_LIMIT = 2.0 ** -10


def dot(a, b):
    """``a . b`` over the last axis, (..., 3) x (..., 3) -> (...): ``(a_0 b_0 + a_1 b_1) + a_2 b_2``, the order and
    rounding of ``np.sum(a * b, axis=-1)`` (bit-identical, tested) at a seventh of its time on (N, 3) rows; other
    lengths by ``np.sum``."""
    a, b = np.asarray(a), np.asarray(b)
    if a.ndim == 0 or b.ndim == 0 or a.shape[-1] != 3 or b.shape[-1] != 3:
        return np.sum(a * b, axis=-1)
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


_dot = dot


# --------------------------------------------------------------------------- common.glsl
def plain_normalize(x):
    """The textbook normalisation (common.glsl): ``x / |x|`` with ``|x|^2`` formed from the raw coordinates, always
    valid; the same returns as `safe_normalize` ((..., 3) -> valid (...), x_hat (..., 3), length (...))."""
    x = np.asarray(x)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore", under="ignore"):
        xx = _dot(x, x).astype(x.dtype, copy=False)
        x_hat = (x * (1 / np.sqrt(xx))[..., None]).astype(x.dtype, copy=False)  # x * inversesqrt(x.x), as in GLSL
        length = np.sqrt(xx).astype(x.dtype, copy=False)
    return np.ones(x.shape[:-1], dtype=bool), x_hat, length


def safe_normalize(x):
    """Scaled normalisation (common.glsl).

    Parameters
    ----------
    x : (..., 3) ndarray

    Returns
    -------
    valid : (...) bool ndarray
        ``0 < max|x_i| <= FLT_MAX`` (false for zero, NaN or Inf vectors).
    x_hat : (..., 3) ndarray
        ``x / |x|``, 0 where not valid.
    length : (...) ndarray
        ``|x|`` computed as ``s sqrt((x/s).(x/s))``, 0 where not valid.
    """
    x = np.asarray(x)
    a = np.abs(x)
    # max|x_i| of the three components pairwise: exact as np.max (NaN too), without a reduction along a short axis
    s = np.maximum(np.maximum(a[..., 0], a[..., 1]), a[..., 2]) if x.shape[-1] == 3 else np.max(a, axis=-1)
    valid = (s > 0) & (s <= FLT_MAX)
    everywhere = bool(valid.all())  # then the masks below pick their first value throughout: left out
    s_safe = (s if everywhere else np.where(valid, s, 1)).astype(x.dtype, copy=False)[..., None]
    with np.errstate(invalid="ignore", over="ignore"):
        y = x / s_safe if everywhere else np.where(valid[..., None], x / s_safe, 0)
        y = y.astype(x.dtype, copy=False)
        yy = (_dot(y, y) if everywhere else np.where(valid, _dot(y, y), 1)).astype(x.dtype, copy=False)
        root = np.sqrt(yy)
        length = s_safe[..., 0] * root if everywhere else np.where(valid, s_safe[..., 0] * root, 0)
        length = np.asarray(length).astype(x.dtype, copy=False)
        x_hat = (y * (1 / root)[..., None]).astype(x.dtype, copy=False)  # y * inversesqrt(y.y), as in GLSL
    return valid, x_hat, length


def frame_from_tangent(n, tangent):
    """The tangent and bitangent of the shading frame (common.glsl).

    Parameters
    ----------
    n : (N, 3) ndarray
        Unit normals.
    tangent : (N, 4) ndarray
        Interpolated tangents, handedness in w.

    Returns
    -------
    t, b : (N, 3) ndarray
        ``t = normalize(tangent.xyz - (n.tangent.xyz) n)``; where that is zero or not finite, or
        the tangent is parallel to n (``|projection| <= FRAME_PARALLEL_LIMIT |n.tangent.xyz|``), the
        tangent of Duff et al.'s orthonormal basis around n; ``b = sign(w) cross(n, t)``.
    """
    n = np.asarray(n)
    tangent = np.asarray(tangent, dtype=n.dtype)
    xyz = tangent[..., :3]
    along = _dot(n, xyz)
    projected, t, length = safe_normalize(xyz - along[..., None] * n)
    projected = projected & (length > FRAME_PARALLEL_LIMIT * np.abs(along))
    s = np.where(n[..., 2] >= 0, 1.0, -1.0).astype(n.dtype, copy=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = -1.0 / (s + n[..., 2])
        fallback = np.stack([1.0 + s * n[..., 0] * n[..., 0] * a, s * n[..., 0] * n[..., 1] * a, -s * n[..., 0]], axis=-1)
    t = np.where(projected[..., None], t, fallback).astype(n.dtype, copy=False)
    b = (np.where(tangent[..., 3] < 0, -1.0, 1.0)[..., None] * np.cross(n, t)).astype(n.dtype, copy=False)
    return t, b


def shading_frame(n, tangent=None, uv=None, key=None):
    """The `ShadingFrame` of shading points (common.glsl ``shading_frame``): ``t``, ``b`` from
    `frame_from_tangent` where ``key.has_tangent``; ``uv`` where ``key.has_uv``."""
    if key is not None and key.has_tangent:
        t, b = frame_from_tangent(n, tangent)
        return ShadingFrame(n, t, b, uv if key.has_uv else None)
    return ShadingFrame(n, None, None, uv if key is not None and key.has_uv else None)


# --------------------------------------------------------------------------- normal_map.glsl
def surface_normal(n, t, b, texel, scale):
    """The normal-mapped normal (normal_map.glsl): ``normalize(t (s m.x) + b (s m.y) + n m.z)``, ``m = 2 texel - 1``;
    ``n`` where that does not normalise.

    Parameters
    ----------
    n, t, b : (N, 3) ndarray
        The shading frame (`shading_frame`).
    texel : (N, 3) ndarray
        The normal texture's filtered linear value in [0, 1].
    scale : float or (N,) ndarray
        glTF's ``normalTexture.scale``.

    Returns
    -------
    (N, 3) ndarray
        Unit normals.
    """
    n = np.asarray(n)
    dtype = n.dtype
    m = (np.asarray(texel, dtype) * dtype.type(2) - dtype.type(1)).astype(dtype, copy=False)
    s = np.asarray(scale, dtype)[..., None] if np.ndim(scale) else dtype.type(scale)
    p = (t * (m[..., 0:1] * s) + b * (m[..., 1:2] * s) + n * m[..., 2:3]).astype(dtype, copy=False)
    valid, mapped, _ = safe_normalize(p)
    return np.where(valid[..., None], mapped, n).astype(dtype, copy=False)


# --------------------------------------------------------------------------- lights.glsl
def point_irradiance(intensity, d, textbook=False):
    """E1 as ``min((I / d) / d, FLT_MAX)`` (lights.glsl); ``textbook``: its ``NAIVE_FALLOFF`` form ``I / (d d)``, which
    ``numerics='auto'`` compiles where the ranges prove it (`glphong.shaders.numerics`).

    Parameters
    ----------
    intensity : (..., 3) ndarray
        ``Phi / (4 pi)`` [W/sr].
    d : (...) ndarray
        Distance [m], > 0.

    Returns
    -------
    (..., 3) ndarray
        Irradiance [W/m^2].
    """
    d = np.asarray(d)[..., None]
    with np.errstate(over="ignore", under="ignore", divide="ignore"):
        return intensity / (d * d) if textbook else np.minimum((intensity / d) / d, FLT_MAX)


def range_window(d, range_):
    """KHR_lights_punctual's range window ``clamp(1 - (d/range)^4, 0, 1)`` in lights.glsl's factored form
    ``clamp(((range - d)/range) (1 + t) (1 + t^2), 0, 1)``, ``t = d/range``.

    Parameters
    ----------
    d : (...) ndarray
        Distance [m].
    range_ : () or (...) ndarray
        The light's range [m], > 0.

    Returns
    -------
    (...) ndarray
        The window, in [0, 1].
    """
    d = np.asarray(d)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        t = d / range_
        return np.clip(((range_ - d) / range_) * (1 + t) * (1 + t * t), 0, 1)


# --------------------------------------------------------------------------- lobe.glsl
def _series_terms(dtype):
    """Terms of the artanh series: 8 in float32, exactly as lobe.glsl; in float64, as many as
    sigma <= 1/3 needs to reach its precision (16)."""
    if np.dtype(dtype) == np.float32:
        return 8
    eps = np.finfo(dtype).eps
    k = 0
    while (1.0 / 9.0) ** k / (2 * k + 1) > eps / 4:
        k += 1
    return k


def log_one_minus_series(delta):
    """``ln(1 - delta)`` for ``0 <= delta < 1/2`` as ``-2 artanh(delta / (2 - delta))`` by its odd series (lobe.glsl;
    8 terms in float32 as in the GLSL, as many as float64 needs otherwise); ``(...)`` -> ``(...)``."""
    delta = np.asarray(delta)
    dtype = delta.dtype if delta.dtype.kind == "f" else np.float64
    delta = delta.astype(dtype)
    with np.errstate(divide="ignore", invalid="ignore"):
        two_sigma = ((2 * delta) / (2 - delta)).astype(dtype, copy=False)
        t = (0.25 * (two_sigma * two_sigma)).astype(dtype, copy=False)
        series = np.zeros_like(two_sigma)
        for k in reversed(range(_series_terms(dtype))):
            series = (series * t + dtype.type(1.0) / dtype.type(2 * k + 1)).astype(dtype, copy=False)
    return (-two_sigma * series).astype(dtype, copy=False)


def log_one_minus(delta):
    """``ln(1 - delta)`` for ``0 <= delta < 1`` (lobe.glsl): `log_one_minus_series` for ``delta < 1/2``,
    ``log(1 - delta)`` above."""
    delta = np.asarray(delta)
    dtype = delta.dtype if delta.dtype.kind == "f" else np.float64
    delta = delta.astype(dtype)
    small = delta < 0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        direct = np.log(np.where(small, 0.5, 1 - delta)).astype(dtype, copy=False)
    return np.where(small, log_one_minus_series(np.where(small, delta, 0)), direct).astype(dtype, copy=False)


def lobe_from_delta(delta, q, tail_zero=False):
    """``(1 - delta)^q``, stable for q up to FLT_MAX (lobe.glsl).

    Returns 1 for q == 0, 0 for delta >= 1, else ``exp(max(q ln(1 - delta), -104))``; ``q`` a scalar or
    an array broadcasting with ``delta`` (a per-point exponent).  ``tail_zero``: the ``LOBE_TAIL_ZERO`` form, 0
    from delta = 1/2 on (the same values where every q is at least ``glphong.shaders.numerics.LOBE_TAIL_Q``).
    """
    delta = np.asarray(delta)
    dtype = delta.dtype if delta.dtype.kind == "f" else np.float64
    q = np.asarray(q, dtype=dtype)
    inside = delta < (0.5 if tail_zero else 1)
    with np.errstate(over="ignore", invalid="ignore"):
        value = np.exp(np.maximum(q * log_one_minus(np.where(inside, delta, 0)), dtype.type(-104)))
    value = np.where(inside, value, 0)
    return np.where(q == 0, 1, value).astype(dtype, copy=False)


def phong_delta(n, wi, wo):
    """``|r - v|^2 / 2`` with ``r = 2 (n.l) n - l`` (lobe.glsl); unit (..., 3) inputs -> (...)."""
    r = 2 * _dot(n, wi)[..., None] * n - wi
    e = r - wo
    return 0.5 * _dot(e, e)


def phong_lobe(n, wi, wo, q):
    """``max(v.r, 0)^q`` = `lobe_from_delta` of `phong_delta` (lobe.glsl); (...)."""
    return lobe_from_delta(phong_delta(n, wi, wo), q)


#: lobe.glsl BLINN_HALF_FLOOR = 2^-20: |l + v| at or below it gives a zero Blinn lobe
BLINN_HALF_FLOOR = 2.0 ** -20


def blinn_delta(n, wi, wo):
    """Blinn's ``delta = |h - n|^2 / 2`` (lobe.glsl).

    Returns
    -------
    valid : (...) bool ndarray
        ``n.v > 0`` and ``|l + v| > BLINN_HALF_FLOOR``.
    delta : (...) ndarray
        ``|h - n|^2 / 2``; 2 where not valid.
    """
    ok_h, h, h_len = safe_normalize(wi + wo)
    valid = (_dot(n, wo) > 0) & ok_h & (h_len > BLINN_HALF_FLOOR)
    e = h - n
    return valid, np.where(valid, 0.5 * _dot(e, e), 2).astype(e.dtype, copy=False)


def blinn_lobe(n, wi, wo, q):
    """``max(n.h, 0)^q``, 0 where `blinn_delta` is not valid (lobe.glsl); (...)."""
    valid, delta = blinn_delta(n, wi, wo)
    return np.where(valid, lobe_from_delta(delta, q), 0).astype(delta.dtype, copy=False)


def half_cosine(wi, wo):
    """``h.l`` with ``h = (l + v)/|l + v|``, 0 where ``l + v`` does not normalise (lobe.glsl); (...)."""
    ok, h, _ = safe_normalize(wi + wo)
    return np.where(ok, _dot(h, wi), 0).astype(h.dtype, copy=False)


# --------------------------------------------------------------------------- fresnel.glsl
def fresnel_schlick(f0, c):
    """Schlick's ``f0 + (1 - f0)(1 - c)^5`` with ``c`` clamped to [0, 1] (fresnel.glsl).

    f0 (3,) in [0, 1], c (...) -> (..., 3), dimensionless.
    """
    c = np.asarray(c)
    m = np.clip(1 - c, 0, 1)
    m2 = m * m
    return f0 + (1 - f0) * (m2 * m2 * m)[..., None]


def fresnel_dielectric(ior, c):
    """The exact unpolarised dielectric reflectance (fresnel.glsl): ior () > 0, c (...) -> (...).

    ``(g - c)^2 / (2 (g + c)^2) (1 + (c (g + c) - 1)^2 / (c (g - c) + 1)^2)``, ``g^2 = ior^2 + c^2 - 1``,
    with ``g - c = (ior^2 - 1)/(g + c)``; 1 under total internal reflection and at ``c = 0``.
    """
    c = np.clip(np.asarray(c), 0, 1)
    dtype = c.dtype if c.dtype.kind == "f" else np.float64
    ior = np.asarray(ior, dtype)
    a = (ior - 1) * (ior + 1)
    g2 = a + c * c
    g = np.sqrt(np.maximum(g2, 0))
    g_plus_c = g + c
    safe = np.maximum(g_plus_c, dtype.type(1e-30))
    with np.errstate(over="ignore", invalid="ignore"):
        ratio = (a / safe) / safe
        g_minus_c = a / safe
        q = (c * g_plus_c - 1) / (c * g_minus_c + 1)
        f = 0.5 * (ratio * ratio) * (1 + q * q)
    return np.where((g2 < 0) | (g_plus_c <= 0), 1, np.minimum(f, 1)).astype(dtype, copy=False)


# --------------------------------------------------------------------------- angle.glsl
def atan2_first_quadrant(y, x):
    """``atan(y / x)`` [rad] in [0, pi/2] for ``y, x >= 0``, 0 where both are 0 (angle.glsl): exact here
    (``numpy.arctan2``); the GLSL evaluates Cephes' atanf polynomial, good to 3 ulp (GLSL's own atan
    is not: 2e-5 relative measured on llvmpipe).  (...) -> (...)."""
    return np.arctan2(y, x)


# --------------------------------------------------------------------------- shade.glsl


def light_term(response, irradiance):
    """``response * E``, exactly 0 where ``E = 0`` (shade.glsl): an overflowed response never makes NaN."""
    with np.errstate(invalid="ignore", over="ignore"):
        value = np.where(irradiance == 0, 0.0, response * irradiance)
        return value.astype(np.result_type(response, irradiance), copy=False)


def perpendiculars(v):
    """Two unit vectors perpendicular to each row of ``v`` (..., 3) and to each other: ``a = normalize(v x h)`` with
    ``h`` the x axis (the y axis where ``|v_x| >= 0.9``), and ``b = v x a`` (unit where ``v`` is)."""
    helper = np.where(np.abs(v[..., :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    a = np.cross(v, helper)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    return a, np.cross(v, a)


def microfacet_geometry(n, wi, wo, n_dot_l):
    """The half-vector geometry of the microfacet models (microfacet.glsl): Cook-Torrance's and glTF's.

    Parameters
    ----------
    n, wi, wo : (..., 3) ndarray
        Unit normal, directions toward the light and the viewer.
    n_dot_l : (...) ndarray

    Returns
    -------
    valid : (...) bool ndarray
        ``l + v`` normalises, ``n.v > 0`` and ``n.l > 0``.
    n_dot_v, n_dot_h, h_dot_l, tan2 : (...) ndarray
        ``n.v``; ``n.h = (n.l + n.v)/|l + v|``; ``h.l = |l + v|/2``; ``tan^2(theta_h) = delta (2 - delta)
        / (n.h)^2`` with ``delta = |h - n|^2 / 2``.  1, 1, 1 and 0 where not valid.
    """

    ok, h, h_len = safe_normalize(wi + wo)
    dtype = h.dtype
    one = dtype.type(1)
    nv = _dot(n, wo).astype(dtype, copy=False)
    n_dot_l = np.asarray(n_dot_l).astype(dtype)
    valid = ok & (nv > 0) & (n_dot_l > 0)
    length = np.where(valid, h_len, one).astype(dtype, copy=False)
    with np.errstate(divide="ignore", over="ignore", under="ignore", invalid="ignore"):
        nh = np.where(valid, (n_dot_l + nv) / length, one).astype(dtype, copy=False)
        e = h - n
        delta = (dtype.type(0.5) * _dot(e, e)).astype(dtype, copy=False)
        sin2 = np.maximum(delta * (dtype.type(2) - delta), dtype.type(0)).astype(dtype, copy=False)
        tan2 = np.where(valid, sin2 / (nh * nh), dtype.type(0)).astype(dtype, copy=False)
    return (valid, np.where(valid, nv, one).astype(dtype, copy=False), nh,
            (dtype.type(0.5) * length).astype(dtype, copy=False), tan2)


def microfacet_ggx(tan2, a2):
    """GGX ``D = (a2 r) r / pi`` [1/sr], ``r = 1 + (1 - a2)/(a2 + tan2)`` (microfacet.glsl), ``r`` and ``D`` at most
    FLT_MAX; 0 where ``a2 + tan2 = 0``.  ``tan2`` (...) >= 0 (may be Inf), ``a2 = alpha^2`` (...) >= 0."""
    tan2 = np.asarray(tan2)
    dtype = tan2.dtype
    a2 = np.asarray(a2).astype(dtype)
    big = dtype.type(FLT_MAX)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        s = (a2 + tan2).astype(dtype, copy=False)
        r = (dtype.type(1) + (dtype.type(1) - a2) / s).astype(dtype, copy=False)
        value = ((a2 * r) * (np.minimum(r, big) * dtype.type(1 / np.pi))).astype(dtype, copy=False)
        return np.where(s > 0, np.minimum(value, big), dtype.type(0)).astype(dtype, copy=False)
