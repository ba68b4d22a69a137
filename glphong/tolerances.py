"""The tolerance band GPU float32 results are held to against the float64 twin (docs/design.md section 4).

With ``eps = 2^-24`` (float32 unit roundoff) and the constants below, the band
around the twin's value of each term is:

- Lambert: ``k_d E [max(n.l - D eps, 0), n.l + D eps] (1 +- A eps)``.
- Lobe: the chord ``c = sqrt(2 delta)`` widened by ``+-C eps`` (for Blinn scaled by
  ``max(1, 2/|l + v|)``, the conditioning of the half vector), mapped through
  ``(1 - c^2/2)^q``, then widened by ``(1 +- eps (A + B lambda))``, ``lambda = -ln(lobe)``
  (`lobe_band`; the lobe models' ``band`` methods apply it).
- Other models: their own ``band`` method, or the generic one of
  `glphong.materials.MaterialModel.band` (the twin's sensitivity to a few ulps of its inputs).
- Gates: where ``|n.l| <= D eps`` (Blinn: also ``|n.v| <= D eps``, or ``|l + v|`` within
  a factor 4 of its floor) either outcome of the gate is accepted.
- Ambient terms: ``(1 +- A eps)``.  The sum over terms widens by ``(1 +- m eps)`` for m terms.
- Results below FLT_MIN may be flushed: the lower bound is 0 there; above FLT_MAX the
  upper bound is +inf.

The constants held with zero failures on a 101k-pixel stress set (q up to 1e7,
grazing lights, d in [1e-3, 1e3]) on llvmpipe.  They live here and nowhere else.
"""
from dataclasses import dataclass

import numpy as np

from . import reference as ref

__all__ = ["EPS", "FLT_MIN", "FLT_MAX", "BandConstants", "BAND", "lobe_band", "response_band", "point_band",
           "radiance_band", "input_bounds"]

EPS = 2.0 ** -24
FLT_MIN = float(np.finfo(np.float32).tiny)
FLT_MAX = float(np.finfo(np.float32).max)


@dataclass(frozen=True)
class BandConstants:
    """Multipliers of eps in the band (docs/design.md section 4).

    Attributes
    ----------
    A : float
        Relative error of products, quotients and sums of a term.
    B : float
        Relative error of the lobe per unit of ``lambda = -ln(lobe)`` (exp's ``2|x|`` ulp).
    C : float
        Absolute error of the unit vectors' chord ``|r - v|`` (or ``|h - n|``).
    D : float
        Absolute error of ``n.l`` and ``n.v``.
    T : float
        Error of a filtered texture value as a fraction of the spread of the texels it weights
        (`glphong.materials.surface.surface_texture_band`).  GL does not bound filter-weight precision;
        2^-7 covers 8-bit weights (Direct3D's minimum).  llvmpipe measured 5.6e-5 (256x256 renders of
        64- and 1024-texel textures, float16 and float32 texels, trilinear, lod 0 to 8); the test
        (tests/test_surface_inputs.py) holds it below 2^-12 beyond 16 ulps of the texels' magnitude.
    """

    A: float = 16.0
    B: float = 4.0
    C: float = 6.0
    D: float = 8.0
    T: float = 2.0 ** -7


BAND = BandConstants()


def lobe_band(delta, q, chord_scale=1.0, band=BAND):
    """Interval of float32 lobe values consistent with a float64 ``delta``.

    Parameters
    ----------
    delta : (...) float64 ndarray
        Distance from the lobe peak, ``1 - cos``.
    q : float
        Exponent.
    chord_scale : float or (...) ndarray
        Factor on the chord widening ``C eps`` (the Blinn half-vector conditioning).
    band : BandConstants

    Returns
    -------
    low, high : (...) float64 ndarray
    """
    delta = np.asarray(delta, dtype=np.float64)
    chord = np.sqrt(2.0 * np.maximum(delta, 0.0))
    width = band.C * EPS * chord_scale
    high = ref.lobe_from_delta(0.5 * np.maximum(chord - width, 0.0) ** 2, q)
    low = ref.lobe_from_delta(0.5 * (chord + width) ** 2, q)

    def widen(value, sign):
        with np.errstate(divide="ignore"):
            lam = -np.log(np.maximum(value, np.finfo(np.float64).tiny))
        return value * (1.0 + sign * EPS * (band.A + band.B * lam))

    low = widen(low, -1.0)
    return np.where(low < FLT_MIN, 0.0, low), widen(high, +1.0)


def input_bounds(uv, color, lod, key, u, band=BAND):
    """The surface inputs ``scale * T(uv) * C`` (`glphong.reference.material_inputs`) and the intervals the
    GPU's values lie in, from one sampling of each texture.

    The texture value's interval is `glphong.materials.surface.surface_texture_band`; scale and
    colour are exact float32 inputs (>= 0), so the products carry the interval's ends, and the two
    float32 products add ``2 eps`` relative.

    Returns
    -------
    values : dict of str to (N, 3) float64 ndarray
    bounds : dict of str to (low, high)
        Both by uniform name.
    """
    from .materials.surface import surface_texture_band

    stacked = ref.material_inputs(uv, color, lod, key, u,
                                  sample=lambda image, at, level: np.stack(surface_texture_band(image, at, level, band)))
    values, bounds = {}, {}
    for name, v in stacked.items():
        value, low, high = v if v.ndim == 3 else (v, v, v)  # (value, low, high), or exact (no texture)
        values[name], bounds[name] = value, (low * (1 - 2 * EPS), high * (1 + 2 * EPS))
    return values, bounds


def _input_ends(f):
    """``(low, high)``: the surface inputs at the two ends of their intervals (None, None without inputs)."""
    if not f.inputs:
        return None, None
    bounds = f.input_bounds
    if bounds is None:  # no intervals asked for: the values themselves
        return f.inputs, f.inputs
    return {k: lo for k, (lo, _) in bounds.items()}, {k: hi for k, (_, hi) in bounds.items()}


def point_band(key, u, position, n, n_valid, material, band=BAND):
    """Interval the GPU's ``shade_point()`` must return at given points.

    Each lit term contributes its own band (`glphong.materials.MaterialModel.band`: the model's
    derived band, or the generic one from the twin's sensitivity), times the irradiance widened
    by ``(1 +- A eps)``.  Where ``|n.l| <= D eps`` either side of the light gate is accepted: there
    the lower bound is 0 and a term's band is asked at its (possibly non-positive) ``n.l``, which it
    must bound over ``(0, n.l + D eps]``.

    Parameters
    ----------
    key : glphong.key.ProgramKey
    u : dict of str to ndarray
        The program's uniforms as float64.
    position : (N, 3) float64 ndarray
    n : (N, 3) float64 ndarray or ShadingFrame
        Unit normals (as `glphong.reference.safe_normalize` returns them), or the shading frame.
    n_valid : (N,) bool ndarray
    material : glphong.materials.Material
    band : BandConstants

    Returns
    -------
    low, high : (N, 3) float64 ndarray
    """
    f = n if hasattr(n, "n") else ref.shading_frame(np.asarray(n), key=key)
    low_inputs, high_inputs = _input_ends(f)
    lo = ref.material_emission(key, u, position.shape, np.float64, inputs=low_inputs) * (1 - band.A * EPS)
    hi = ref.material_emission(key, u, position.shape, np.float64, inputs=high_inputs) * (1 + band.A * EPS)
    terms = int(key.has_ka) + sum(1 for t in key.terms if t.ambient)
    if key.num_lights:
        wo, lit = ref.view_direction(position, n_valid, u.get("u_eye"), key)
        tol = band.D * EPS
        for valid, wi, irradiance in ref.incident_light(position, key, u):
            terms += 1
            n_dot_l = ref._dot(f.n, wi)
            certain = (lit & valid & (n_dot_l > tol))[..., None]
            possible = lit & valid & (n_dot_l > -tol)
            f_lo = np.zeros_like(position)
            f_hi = np.zeros_like(position)
            if possible.any():
                f_lo[possible], f_hi[possible] = response_band(key, u, f.select(possible), wi[possible],
                                                               wo[possible], n_dot_l[possible], material, band)
            with np.errstate(over="ignore", invalid="ignore"):
                # an irradiance below FLT_MIN may be flushed to 0 on the GPU, and the term with it
                e_lo = np.where(irradiance < FLT_MIN, 0.0, irradiance)
                t_lo = np.nan_to_num(ref.light_term(f_lo, e_lo) * (1 - band.A * EPS), nan=0.0)
                t_hi = np.nan_to_num(ref.light_term(f_hi, irradiance) * (1 + band.A * EPS), nan=np.inf, posinf=np.inf)
            lo = lo + np.where(certain, t_lo, 0.0)
            hi = hi + np.where(possible[..., None], t_hi, 0.0)
    low = lo * (1 - terms * EPS)
    high = hi * (1 + terms * EPS)
    return np.where(low < FLT_MIN, 0.0, low), np.where(high > FLT_MAX, np.inf, high)


def response_band(key, u, f, wi, wo, n_dot_l, material, band=BAND):
    """Interval of the GLSL ``material_response()``: the sum of the lit terms' bands.

    Parameters
    ----------
    key : glphong.key.ProgramKey
    u : dict of str to ndarray
        Uniforms as float64 (the terms' parameters are read from them).
    f : ShadingFrame
    wi, wo : (N, 3) float64 ndarray
    n_dot_l : (N,) float64 ndarray
        May be down to ``-D eps`` where the light gate is uncertain.
    material : glphong.materials.Material
    band : BandConstants

    Returns
    -------
    low, high : (N, 3) float64 ndarray
        Widened by ``(1 -+ m eps)`` for the sum of m terms.
    """
    models = {term.name: term for term in material.components}
    low = np.zeros(np.shape(wi))
    high = np.zeros(np.shape(wi))
    for term_key in key.lit_terms:
        term = models[term_key.name]
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if term.surface_inputs():  # the band at both ends of the inputs' intervals (first order inside)
                ends = [term.band(f, wi, wo, n_dot_l, term.values_from_uniforms(u, inputs=inputs), band)
                        for inputs in _input_ends(f)]
                t_lo, t_hi = np.minimum(ends[0][0], ends[1][0]), np.maximum(ends[0][1], ends[1][1])
            else:
                t_lo, t_hi = term.band(f, wi, wo, n_dot_l, term.values_from_uniforms(u), band)
        # a term's float32 result below FLT_MIN in magnitude may be flushed to 0 (e.g. ks * lobe with
        # the lobe just above FLT_MIN): the band then reaches 0
        t_lo = np.where((t_lo > 0) & (t_lo < FLT_MIN), 0.0, t_lo)
        t_hi = np.where((t_hi < 0) & (t_hi > -FLT_MIN), 0.0, t_hi)
        low, high = low + t_lo, high + t_hi
    m = max(len(key.lit_terms) - 1, 0)
    return low * (1 - m * EPS), high * (1 + m * EPS)


def radiance_band(scene, gbuffer, band=BAND):
    """Per-pixel interval the GPU's radiance must lie in (`point_band` on every covered pixel).

    Parameters
    ----------
    scene : glphong.Scene
    gbuffer : glphong.GBuffer
    band : BandConstants

    Returns
    -------
    low, high : (H, W, 3) float64 ndarray
        0 where not covered.
    """
    low = np.zeros(gbuffer.position.shape)
    high = np.zeros(gbuffer.position.shape)
    for selection, obj, key, u, position, f, n_valid in ref.shade_inputs(scene, gbuffer, band=band):
        low[selection], high[selection] = point_band(key, u, position, f, n_valid, obj.material, band)
    return low, high
