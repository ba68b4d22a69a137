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

The constants and the lobe's band are `glphong.twin.band` (re-exported here); this module holds the
band of a whole image, term by term.
"""
import numpy as np

from glphong.checks import reference as ref
from glphong.checks.reference import input_bounds  # noqa: F401 - re-exported
from glphong.checks.uniform_values import values_from
from glphong.twin.band import BAND, EPS, FLT_MAX, FLT_MIN, BandConstants, lobe_band  # noqa: F401 - re-exported

__all__ = ["EPS", "FLT_MIN", "FLT_MAX", "BandConstants", "BAND", "lobe_band", "response_band", "point_band",
           "radiance_band", "input_bounds"]


def _input_ends(f):
    """``(low, high)``: the surface inputs at the two ends of their intervals (None, None without inputs)."""
    if not f.inputs:
        return None, None
    bounds = f.input_bounds
    if bounds is None:  # no intervals asked for: the values themselves
        return f.inputs, f.inputs
    return {k: lo for k, (lo, _) in bounds.items()}, {k: hi for k, (_, hi) in bounds.items()}


def _textured_band(term, f, wi, wo, n_dot_l, u, band):
    """The band of a term with surface inputs: its band at the inputs' values, widened by the response's change as
    each input moves to either end of its interval alone (first order: the deviations add up worst-case, as the
    generic band's do; a product of two inputs, base colour times metallic, and a response that is not monotone in
    one, GGX in roughness, are bounded to first order over intervals a few texel steps of ``T`` wide)."""
    values = term.values_from_uniforms(u, inputs=f.inputs)
    low, high = term.band(f, wi, wo, n_dot_l, values, band)
    if f.input_bounds is None:
        return low, high
    at = np.maximum(n_dot_l, np.finfo(np.float64).tiny)
    base = np.asarray(term.response(f, wi, wo, at, values), dtype=np.float64)
    read = [term.uniform_name(param) for param in term.surface_inputs() if param not in (term.emission, term.occluded_by)]
    for name in (name for name in read if name in f.input_bounds):  # the response's own inputs
        up, down = np.zeros_like(base), np.zeros_like(base)
        for end in f.input_bounds[name]:
            moved = term.values_from_uniforms(u, inputs={**f.inputs, name: end})
            delta = np.nan_to_num(np.asarray(term.response(f, wi, wo, at, moved), dtype=np.float64) - base, nan=0.0)
            up, down = np.maximum(up, delta), np.minimum(down, delta)
        low, high = low + down, high + up
    return low, high


def point_band(key, u, position, n, n_valid, material, band=BAND, incident=None, view=None):
    """Interval the GPU's ``shade_point()`` must return at given points.

    Each lit term contributes its own band (`glphong.materials.MaterialModel.band`: the model's
    derived band, or the generic one from the twin's sensitivity), times the irradiance's interval (the
    light kind's ``band``, `glphong.lights.LightModel.band`) widened by ``(1 +- A eps)``.  Where ``|n.l| <= D eps`` either side of the light gate is accepted: there
    the lower bound is 0 and a term's band is asked at its (possibly non-positive) ``n.l``, which it
    must bound over ``(0, n.l + D eps]``.

    Parameters
    ----------
    key : glphong.shaders.key.ProgramKey
    u : dict of str to ndarray
        The program's uniforms as float64.
    position : (N, 3) float64 ndarray
    n : (N, 3) float64 ndarray or ShadingFrame
        Unit normals (as `glphong.reference.safe_normalize` returns them), or the shading frame.
    n_valid : (N,) bool ndarray
    material : glphong.materials.Material
    band : BandConstants
    incident : list, optional
        ``incident_light(position, key, u, band=band)`` where the caller has it already (`glphong.checks.verify`'s
        twin shares it).
    view : (wo, lit), optional
        ``glphong.checks.reference.view_direction(position, n_valid, u.get("u_eye"), key)`` where the caller has it.

    Returns
    -------
    low, high : (N, 3) float64 ndarray
    """
    f = n if hasattr(n, "n") else ref.shading_frame(np.asarray(n), key=key)
    low_inputs, high_inputs = _input_ends(f)
    lo = ref.material_emission(key, u, position.shape, np.float64, inputs=low_inputs) * (1 - band.A * EPS)
    hi = ref.material_emission(key, u, position.shape, np.float64, inputs=high_inputs) * (1 + band.A * EPS)
    terms = int(key.has_ka) + sum(1 for t in key.terms if t.ambient) + sum(1 for t in key.terms if t.emission)
    if key.num_lights:
        wo, lit = ref.view_direction(position, n_valid, u.get("u_eye"), key) if view is None else view
        tol = band.D * EPS
        lights = ref.incident_light(position, key, u, band=band) if incident is None else incident
        for i, (valid, wi, irradiance, (e_low, e_high)) in enumerate(lights):
            terms += 1
            if f.visibility is not None and f.visibility[i] is not None:  # the shadow map's interval
                _, v_low, v_high = f.visibility[i]
                e_low, e_high = e_low * v_low[:, None], e_high * v_high[:, None]
            n_dot_l = ref._dot(f.n, wi)
            reached = lit & valid
            # the points the term may reach, by index: the term is 0 elsewhere (each point's arithmetic is its own)
            possible = np.flatnonzero(reached & (n_dot_l > -tol))
            t_lo, t_hi = np.zeros_like(position), np.zeros_like(position)
            if possible.size:
                f_lo, f_hi = response_band(key, u, f.select(possible), wi[possible], wo[possible], n_dot_l[possible],
                                           material, band)
                certain = (n_dot_l[possible] > tol)[..., None]
                with np.errstate(over="ignore", invalid="ignore"):
                    # an irradiance below FLT_MIN may be flushed to 0 on the GPU, and the term with it
                    e_lo = e_low[possible]
                    e_lo = np.where(e_lo < FLT_MIN, 0.0, e_lo)
                    t_lo[possible] = np.where(certain, np.nan_to_num(ref.light_term(f_lo, e_lo) * (1 - band.A * EPS),
                                                                     nan=0.0), 0.0)
                    t_hi[possible] = np.nan_to_num(ref.light_term(f_hi, e_high[possible]) * (1 + band.A * EPS),
                                                   nan=np.inf, posinf=np.inf)
            lo = lo + t_lo
            hi = hi + t_hi
        for e_lo, e_hi in extended_band(key, u, position, f, wo, lit, material, band):
            terms += 1
            lo, hi = lo + e_lo, hi + e_hi
    low = lo * (1 - terms * EPS)
    high = hi * (1 + terms * EPS)
    return np.where(low < FLT_MIN, 0.0, low), np.where(high > FLT_MAX, np.inf, high)


def extended_band(key, u, position, f, wo, lit, material, band=BAND):
    """Per extended light of the key, the interval ``(low, high)`` (each (N, 3)) of its generated loop's ``reflected``
    (docs/design.md section 13): each closed-form term ``k`` times the kind's ``irradiance_band`` or ``lobe_band``
    (``k`` at both ends of its surface input's interval) widened by ``(1 +- A eps)``; each weighted direction as a
    punctual light (the kind's ``sample_band``, the sampled terms' `response_band`, the uncertain gate); the sum of
    ``m`` contributions widened by ``(1 +- m eps)``; 0 where not ``lit``."""
    terms = {t.name: t for t in material.components}
    ends = _input_ends(f)
    tol = band.D * EPS
    for light_key, twin, p, closed, sampled in ref.extended_lights(key, u, np.float64):
        lo, hi = np.zeros_like(position), np.zeros_like(position)
        count = 0
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if any(t.integral.form == "irradiance" for t in closed):
                e_lo, e_hi = twin.irradiance_band(position, f.n, p, band)
            for t in closed:
                k_lo, k_hi = (getattr(v, t.integral.scale) * ref.occlusion_factor(t, v, light_key.occludable) for v in
                              (terms[t.name].values_from_uniforms(u, inputs=i) for i in ends))
                factor = float(np.float32(t.integral.factor))
                if t.integral.form == "irradiance":
                    c_lo, c_hi = e_lo, e_hi
                else:
                    q = float(getattr(terms[t.name].values_from_uniforms(u), t.integral.exponent))
                    c_lo, c_hi = twin.lobe_band(position, f.n, ref.view_reflected(f.n, wo), q, p, band)
                lo = lo + np.minimum(k_lo, k_hi) * factor * c_lo * (1 - 2 * band.A * EPS)
                hi = hi + np.maximum(k_lo, k_hi) * factor * c_hi * (1 + 2 * band.A * EPS)
                count += 1
            for k in range(int(p.defines["MAX_SAMPLES"]) if sampled else 0):
                valid, wi, _ = twin.sample(position, f.n, k, p)
                s_lo, s_hi = twin.sample_band(position, f.n, k, p, band)
                n_dot_l = ref._dot(f.n, wi)
                certain = (valid & (n_dot_l > tol))[..., None]
                possible = valid & (n_dot_l > -tol)
                r_lo, r_hi = np.zeros_like(position), np.zeros_like(position)
                if possible.any():
                    r_lo[possible], r_hi[possible] = response_band(key, u, f.select(possible), wi[possible], wo[possible],
                                                                   n_dot_l[possible], material, band, sampled,
                                                                   light_key.occludable)
                t_lo = np.nan_to_num(ref.light_term(r_lo, np.where(s_lo < FLT_MIN, 0.0, s_lo)) * (1 - band.A * EPS), nan=0.0)
                t_hi = np.nan_to_num(ref.light_term(r_hi, s_hi) * (1 + band.A * EPS), nan=np.inf, posinf=np.inf)
                lo = lo + np.where(certain, t_lo, 0.0)
                hi = hi + np.where(possible[..., None], t_hi, 0.0)
                count += 1
        yield (np.where(lit[:, None], lo * (1 - count * EPS), 0.0), np.where(lit[:, None], hi * (1 + count * EPS), 0.0))


def response_band(key, u, f, wi, wo, n_dot_l, material, band=BAND, term_keys=None, occluded=False):
    """Interval of the GLSL ``material_response()``: the sum of the lit terms' bands.

    Parameters
    ----------
    key : glphong.shaders.key.ProgramKey
    u : dict of str to ndarray
        Uniforms as float64 (the terms' parameters are read from them).
    f : ShadingFrame
    wi, wo : (N, 3) float64 ndarray
    n_dot_l : (N,) float64 ndarray
        May be down to ``-D eps`` where the light gate is uncertain.
    material : glphong.materials.Material
    band : BandConstants
    term_keys : sequence of TermKey, optional
        The terms summed (default the key's lit terms; an extended kind's sampled ones).
    occluded : bool
        Each term's band times its occlusion's interval (an occludable kind's samples).

    Returns
    -------
    low, high : (N, 3) float64 ndarray
        Widened by ``(1 -+ m eps)`` for the sum of m terms.
    """
    models = {term.name: term for term in material.components}
    term_keys = key.lit_terms if term_keys is None else term_keys
    low = np.zeros(np.shape(wi))
    high = np.zeros(np.shape(wi))
    for term_key in term_keys:
        term = models[term_key.name]
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if term.surface_inputs():
                t_lo, t_hi = _textured_band(term, f, wi, wo, n_dot_l, u, band)
            else:
                t_lo, t_hi = term.band(f, wi, wo, n_dot_l, values_from(term, u), band)
        if occluded and term_key.occlusion:  # an occludable light: the term's times its occlusion (>= 0), both ends
            o_lo, o_hi = (ref.occlusion_factor(term_key, term.values_from_uniforms(u, inputs=i), True) for i in _input_ends(f)) \
                if f.inputs else (ref.occlusion_factor(term_key, term.values_from_uniforms(u), True),) * 2
            products = [t_lo * o_lo, t_lo * o_hi, t_hi * o_lo, t_hi * o_hi]
            t_lo, t_hi = np.minimum.reduce(products) * (1 - EPS), np.maximum.reduce(products) * (1 + EPS)
        # a term's float32 result below FLT_MIN in magnitude may be flushed to 0 (e.g. ks * lobe with
        # the lobe just above FLT_MIN): the band then reaches 0
        t_lo = np.where((t_lo > 0) & (t_lo < FLT_MIN), 0.0, t_lo)
        t_hi = np.where((t_hi < 0) & (t_hi > -FLT_MIN), 0.0, t_hi)
        low, high = low + t_lo, high + t_hi
    m = max(len(term_keys) - 1, 0)
    return low * (1 - m * EPS), high * (1 + m * EPS)


def radiance_band(scene, gbuffer, band=BAND, shadows=None):
    """Per-pixel interval the GPU's radiance must lie in (`point_band` on every covered pixel).

    Parameters
    ----------
    scene : glphong.Scene
    gbuffer : glphong.GBuffer
    band : BandConstants
    shadows : (int, int), optional
        The renderer's shadow settings, where a light casts shadows (`glphong.checks.reference.shade_inputs`).

    Returns
    -------
    low, high : (H, W, 3) float64 ndarray
        0 where not covered.
    """
    low = np.zeros(gbuffer.position.shape)
    high = np.zeros(gbuffer.position.shape)
    for selection, obj, key, u, position, f, n_valid in ref.shade_inputs(scene, gbuffer, band=band, shadows=shadows):
        low[selection], high[selection] = point_band(key, u, position, f, n_valid, obj.material, band)
    return low, high
