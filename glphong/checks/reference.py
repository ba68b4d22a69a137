"""The numpy twin of the GLSL shaders (docs/design.md sections 1 and 3).

Every GLSL function of the library chunks (common, lights, lobe, fresnel, shade and the generated
material chunk) has a twin here with the same name, the same argument order and the same
formulation; a model's functions live with its definition (``glphong.materials.<model>``, its
``response`` method the twin of ``<model>_response``).  Only the arithmetic is done in the dtype
of the inputs (float64 for the reference, float32 to study the GPU's formulation on the CPU).
Conventions of the mirror:

- vectors are arrays of shape ``(..., 3)``, scalars per point of shape ``(...)``;
- a GLSL function with ``out`` parameters returns ``(return value, *outs)``;
- uniforms the GLSL reads from globals are passed as the trailing ``uniforms``
  dictionary (the very float32 values the GPU was given), the ``key`` and the ``material``
  (whose terms' twins the generated material chunk calls).

`shade` is the image-level entry: it shades a G-buffer, fragment for fragment.
"""
import sys
from dataclasses import replace

import numpy as np

from glphong.definitions.surface import surface_texture, surface_texture_band
from glphong.definitions.table import uniform_as
from glphong.twin.band import BAND, EPS
from glphong.twin.functions import (BLINN_HALF_FLOOR, FLT_MAX, FRAME_PARALLEL_LIMIT, ShadingFrame, _dot,  # noqa: F401
                                    atan2_first_quadrant, blinn_delta, blinn_lobe, frame_from_tangent, fresnel_dielectric,
                                    fresnel_schlick, half_cosine, light_term, lobe_from_delta, log_one_minus, log_one_minus_series,
                                    microfacet_geometry, microfacet_ggx, plain_normalize,
                                    phong_delta, phong_lobe, point_irradiance, range_window, safe_normalize,
                                    shading_frame, surface_normal)
from glphong.checks.shadows import shadow_visibility
from glphong.checks.uniform_values import values_from
from glphong.twin.area import (area_angle, area_clip, area_clipped_cosine, area_clipped_lobe, area_edge_powers,  # noqa: F401
                               area_polygon_cosine, area_polygon_lobe, area_solid_angle, area_triangle_sample)
from glphong.shaders.generated import closed_form
from glphong.shaders.builders import lod_slots
from glphong.lights import light_for_key
from glphong.materials import registered_models
from glphong.shaders.binding import binding

__all__ = [
    "safe_normalize", "plain_normalize", "log_one_minus_series", "frame_from_tangent", "shading_frame", "surface_normal", "point_irradiance", "range_window", "log_one_minus", "lobe_from_delta",
    "phong_delta", "phong_lobe", "BLINN_HALF_FLOOR", "blinn_delta", "blinn_lobe", "half_cosine",
    "fresnel_schlick", "fresnel_dielectric", "atan2_first_quadrant", "microfacet_geometry", "microfacet_ggx", "incident_light", "material_emission", "material_response", "light_term", "view_direction", "shade_point",
    "shade_inputs", "shade", "input_bounds", "area_angle", "area_clip", "area_polygon_cosine", "area_solid_angle",
    "area_edge_powers", "area_polygon_lobe", "area_clipped_cosine", "area_clipped_lobe", "area_triangle_sample", "extended_reflection", "exact_reflection",
]

def __getattr__(name):
    """A model's twin function by name (``reference.lambert``): each lives with its model in
    ``glphong.materials.<module>``; this finds it in the modules of the registered models."""
    for model in registered_models():
        module = sys.modules.get(model.__module__)
        if name in getattr(module, "__all__", ()):
            return getattr(module, name)
    raise AttributeError(f"module 'glphong.reference' has no attribute {name!r}")


def incident_light(position, key, uniforms, band=None):
    """Direction and irradiance of every light at each point: the generated light loops' heads, each a kind's
    twin ``incident`` (`glphong.lights.LightModel`), in the key's order.

    Parameters
    ----------
    position : (N, 3) ndarray
        World-space points [m].
    key : glphong.shaders.key.ProgramKey
    uniforms : dict of str to ndarray
        The program's uniforms, in the dtype of the computation.
    band : glphong.twin.band.BandConstants, optional
        Also return each irradiance's interval (the kind's ``band``).

    Returns
    -------
    list of (valid, wi, irradiance), or of (valid, wi, irradiance, (low, high)) with ``band``
        Per light, in shader order: ``valid`` (N,) bool (the light reaches the point: its direction
        normalised), ``wi`` (N, 3) unit vector toward the light, ``irradiance`` (N, 3) E [W/m^2].
    """
    out = []
    for light_key in key.lights:
        if light_key.extended:  # integrated over their solid angle: extended_reflection
            continue
        kind = light_for_key(light_key.name, light_key.source_hash)
        twin = kind.twin()
        for j in range(light_key.count):
            p = values_from(kind, uniforms, j, dtype=position.dtype, defines=light_key.defines)
            with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
                computed = valid, wi, irradiance = twin.incident(position, p)
                wi = np.broadcast_to(wi, position.shape)
                irradiance = np.broadcast_to(irradiance, position.shape)
                if band is None:
                    out.append((np.broadcast_to(valid, position.shape[:-1]), wi, irradiance))
                else:
                    out.append((np.broadcast_to(valid, position.shape[:-1]), wi, irradiance,
                                twin.band_given(position, p, band, computed)))
    return out


def _terms(material):
    return {term.name: term for term in material.components}


def material_emission(key, uniforms, shape, dtype, material=None, inputs=None):
    """``k_a + sum_terms (o k L_a + e)`` (the generated material chunk's ``material_emission``: ``o`` a term's
    occlusion, ``e`` what it emits), broadcast to ``shape``;
    ``inputs`` the per-fragment values of surface inputs (`material_inputs`), where the key has them."""
    def value(name, rgb=True):
        v = inputs[name] if inputs is not None and name in inputs else uniforms[name]
        return v[..., None] if not rgb and np.ndim(v) == 1 else v  # a scalar per fragment, (N,), against rgb

    radiance = np.zeros(shape, dtype)
    if key.has_ka:
        radiance = radiance + uniforms["u_ka"]
    for term in key.terms:
        if term.ambient:
            scale = np.float32(term.ambient_scale).astype(dtype)
            answer = value(f"u_{term.name}_{term.ambient_param}") * (scale * uniforms["u_ambient"])
            radiance = radiance + (value(f"u_{term.name}_{term.occlusion}", False) * answer if term.occlusion else answer)
        if term.emission:
            radiance = radiance + value(f"u_{term.name}_{term.emission}")
    return radiance


def material_inputs(uv, color, lod, key, uniforms, sample=None):
    """The surface inputs of the generated material chunk's ``material_inputs(uv, color)``:
    ``u_<model>_<param> = scale * surface_texture(texture, uv) * color``.

    Parameters
    ----------
    uv : (N, 2) ndarray or None
    color : (N, 3) ndarray or None
        The interpolated vertex colour (the G-buffer's), where an input reads it.
    lod : (N, 4) ndarray or None
        The G-buffer's levels of detail, one per texture size (`glphong.shaders.key.lod_slots`).
    key : glphong.shaders.key.ProgramKey
    uniforms : dict
        The program's uniforms (``u_<model>_<param>_scale`` and ``_texture``).
    sample : callable, optional
        ``sample(image, uv, lod)`` in place of `surface_texture`; it may return ``(k, N, 3)`` (several
        arrays that the products broadcast over: `glphong.checks.tolerances.input_bounds` passes the value and
        its interval from one sampling).

    Returns
    -------
    dict of str to (N, 3) (or (k, N, 3)) float64 ndarray
        By uniform name; empty where the key has no surface input.  A scalar's input (one channel) is (N,)
        (or (k, N)).
    """
    sample = surface_texture if sample is None else sample
    out = {}
    textured = list(key.textured_inputs)
    slots, _ = lod_slots([uniforms[f"u_{t}_{p}_texture"] for t, p in textured])
    for term, param, mode in key.inputs:
        name = f"u_{term}_{param}"
        pick = _channel_of(mode)
        value = np.asarray(uniforms[f"{name}_scale"], dtype=np.float64)
        if "texture" in mode:
            value = value * pick(sample(uniforms[f"{name}_texture"], uv, lod[:, slots[textured.index((term, param))]]))
        if "vertex" in mode:
            value = value * pick(color)
        n = len(uv) if uv is not None else len(color)
        out[name] = np.broadcast_to(value, np.broadcast_shapes(np.shape(value), (n, 3) if ":" not in mode else (n,)))
    return out


def _channel_of(mode):
    """What an input of ``mode`` reads of an rgb value (..., 3): all of it, or the one channel after the ':'."""
    if ":" not in mode:
        return lambda rgb: rgb
    index = "rgb".index(mode.split(":")[1])
    return lambda rgb: rgb[..., index]


def input_bounds(uv, color, lod, key, u, band=BAND):
    """The surface inputs ``scale * T(uv) * C`` (`glphong.reference.material_inputs`) and the intervals the
    GPU's values lie in, from one sampling of each texture.

    The texture value's interval is `glphong.definitions.surface.surface_texture_band`; scale and
    colour are exact float32 inputs (>= 0), so the products carry the interval's ends, and the two
    float32 products add ``2 eps`` relative.

    Returns
    -------
    values : dict of str to (N, 3) float64 ndarray
    bounds : dict of str to (low, high)
        Both by uniform name.
    """
    stacked = material_inputs(uv, color, lod, key, u,
                                  sample=lambda image, at, level: np.stack(surface_texture_band(image, at, level, band)))
    values, bounds = {}, {}
    for term, param, mode in key.inputs:
        name = f"u_{term}_{param}"
        v = stacked[name]
        value, low, high = v if "texture" in mode else (v, v, v)  # (value, low, high), or exact (no texture)
        values[name], bounds[name] = value, (low * (1 - 2 * EPS), high * (1 + 2 * EPS))
    return values, bounds


def material_response(f, wi, wo, n_dot_l, key, uniforms, material):
    """Sum of the lit terms' twins (the generated material chunk's ``material_response``); (N, 3)."""
    return terms_response(f, wi, wo, n_dot_l, key.lit_terms, uniforms, _terms(material))


def view_direction(position, n_valid, eye, key):
    """The head of shade.glsl's light loops: ``v`` where a lobe needs it, and which points are lit.

    Returns
    -------
    wo : (N, 3) ndarray
        Unit vectors toward the viewer, ``normalize(e - w x)`` of the homogeneous eye ``(e, w)`` (0 where no
        lit term needs the view: not computed).
    lit : (N,) bool ndarray
        Valid normal and, where the view is needed, a valid view direction.
    """
    if not key.needs_view:
        return np.zeros_like(position), n_valid
    eye = np.asarray(eye)
    if eye.shape[-1] == 3:  # a camera centre: the homogeneous eye (e, 1)
        ok_v, wo, _ = safe_normalize(eye - position)
    else:
        ok_v, wo, _ = safe_normalize(eye[:3] - position * eye[3])
    return wo, n_valid & ok_v


def shade_point(position, n, n_valid, eye, key, uniforms, material, extended=None, incident=None, view=None):
    """E6 at each point (shade.glsl's ``shade_point``).

    Parameters
    ----------
    position : (N, 3) ndarray
        World-space points [m].
    n : (N, 3) ndarray or ShadingFrame
        Unit normals, or the whole shading frame (needed where a term reads t, b or uv).
    n_valid : (N,) bool ndarray
        False where the normal was zero or not finite: emission terms only.
    eye : (4,) or (3,) ndarray or None
        The homogeneous eye ``(e, w)`` (`glphong.Camera.eye`), or a camera centre ``e`` (``w = 1``);
        None where the key needs no view vector.
    key, uniforms
        As in `incident_light`.
    material : glphong.materials.Material
        The material whose terms' twins are summed.
    extended : callable, optional
        What the extended lights reflect, ``extended(position, f, wo, lit, key, uniforms, material) -> (N, 3)``:
        default `extended_reflection` (the shader's methods); `glphong.checks.verify.exact_image` passes the exact
        integrals.
    incident : list, optional
        `incident_light` of these points, where the caller has it already (`glphong.checks.verify.twin_and_band`
        shares it with the band); its first three entries per light are read.
    view : (wo, lit), optional
        `view_direction` of these points, where the caller has it already (`glphong.checks.verify.twin_and_band`).

    Returns
    -------
    (N, 3) ndarray
        Radiance [W/(m^2 sr)].
    """
    f = n if hasattr(n, "n") else shading_frame(np.asarray(n), key=key)
    radiance = material_emission(key, uniforms, position.shape, position.dtype, material, f.inputs)
    if key.num_lights == 0:
        return radiance
    wo, lit = view_direction(position, n_valid, eye, key) if view is None else view
    lights = incident_light(position, key, uniforms) if incident is None else [light[:3] for light in incident]
    for i, (valid, wi, irradiance) in enumerate(lights):
        if f.visibility is not None and f.visibility[i] is not None:  # the ray-cast shadow (checks.shadows)
            irradiance = irradiance * f.visibility[i][0][:, None]
        n_dot_l = _dot(f.n, wi)
        gate = np.flatnonzero(lit & valid & (n_dot_l > 0))  # by index: one search for the gathers and the scatter
        term = np.zeros_like(radiance)
        if gate.size:
            g = f.select(gate)
            with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
                term[gate] = light_term(material_response(g, wi[gate], wo[gate], n_dot_l[gate], key, uniforms, material),
                                        irradiance[gate])
        radiance = radiance + term
    if any(k.extended for k in key.lights):
        radiance = radiance + (extended or extended_reflection)(position, f, wo, lit, key, uniforms, material)
    return radiance


def extended_lights(key, uniforms, dtype, lights=None):
    """Each extended light of the key, in loop order: ``(light_key, twin, p, closed, sampled)`` with ``p`` its
    `ParamValues` and ``closed``/``sampled`` the lit terms (`TermKey`) it reflects in closed form and by samples;
    ``twin`` the scene's light itself where ``lights`` (the scene's lights) is given, else a bare instance of its kind
    (the twin reads only its arguments)."""
    for light_key in key.lights:
        if not light_key.extended:
            continue
        kind = light_for_key(light_key.name, light_key.source_hash)
        closed = [t for t in key.lit_terms if closed_form(t, light_key)]
        sampled = [t for t in key.lit_terms if not closed_form(t, light_key)]
        mine = [light for light in lights if type(light) is kind] if lights is not None else []
        for j in range(light_key.count):
            yield light_key, mine[j] if mine else kind.twin(), \
                kind.values_from_uniforms(uniforms, j, dtype=dtype, defines=light_key.defines), closed, sampled


def view_reflected(n, wo):
    """``reflect(-wo, n) = 2 (n.wo) n - wo``: the axis of the lecture's Phong lobe under an extended light."""
    return -wo - 2.0 * _dot(n, -wo)[..., None] * n


def extended_reflection(position, f, wo, lit, key, uniforms, material):
    """The generated loops over the extended lights (docs/design.md section 13), (N, 3): per light, each closed-form
    term's ``k E(n)`` or ``k_s`` times the lobe integral about ``r_v``, plus the other terms summed over the light's
    weighted directions, gated by ``lit``."""
    terms = _terms(material)
    out = np.zeros_like(position)
    for light_key, twin, p, closed, sampled in extended_lights(key, uniforms, position.dtype):
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            reflected = closed_reflection(position, f, wo, closed, twin, p, light_key, uniforms, terms)
            for k in range(int(p.defines["MAX_SAMPLES"]) if sampled else 0):
                valid, wi, irradiance = twin.sample(position, f.n, k, p)
                n_dot_l = _dot(f.n, wi)
                gate = valid & (n_dot_l > 0)
                if gate.any():
                    g = f.select(gate)
                    term = np.zeros_like(position)
                    term[gate] = light_term(terms_response(g, wi[gate], wo[gate], n_dot_l[gate], sampled, uniforms,
                                                           terms, light_key.occludable), irradiance[gate])
                    reflected = reflected + term
        out = out + np.where(lit[:, None], reflected, 0.0)
    return out


def closed_reflection(position, f, wo, closed, twin, p, light_key, uniforms, terms, factor_dtype=np.float32):
    """What the ``closed`` terms (`TermKey`) reflect of one extended light by its closed forms, (N, 3): each term's
    ``k factor E(n)`` (its irradiance form) or ``k`` times the lobe integral about ``r_v`` (its lobe form), the factor
    rounded to ``factor_dtype`` (float32, as the GLSL's constant; float64 for the exact integral)."""
    reflected = np.zeros_like(position)
    if any(t.integral.form == "irradiance" for t in closed):
        e = twin.irradiance(position, f.n, p)
    for t in closed:
        values = terms[t.name].values_from_uniforms(uniforms, dtype=position.dtype, inputs=f.inputs)
        k = getattr(values, t.integral.scale) * occlusion_factor(t, values, light_key.occludable)
        if t.integral.form == "irradiance":
            reflected = reflected + k * (np.asarray(t.integral.factor, factor_dtype).astype(position.dtype) * e)
        else:
            reflected = reflected + k * twin.lobe(position, f.n, view_reflected(f.n, wo), _exponent(t, values), p)
    return reflected


def _exponent(term_key, values):
    """The lobe exponent ``q`` of a term's lobe form, a number."""
    return float(getattr(values, term_key.integral.exponent))


def exact_reflection(position, f, wo, lit, key, uniforms, material, lights=None, closed_forms=True):
    """The exact integral of every lit term's response over each extended light, ``integral f_r L (n.w)^+ dw``
    [W/(m^2 sr)] (docs/design.md section 13), gated by ``lit``: by the kind's closed forms where they are the exact
    integrals of every lit term (`ExtendedLight.exact_integrals`: a polygon's irradiance and whole-q lobe, a sphere's
    and a disk's irradiance), in float64 with the terms' factors in float64, else by the kind's float64 quadrature of
    their sum (``exact``, whose tolerance is relative to the sum);
    ``lights``: the scene's lights (needed by a kind whose exact integral reads more than its uniforms: an
    environment light's map); ``closed_forms=False``: the quadrature for every light (what the tests compare the
    closed forms with).

    Returns
    -------
    value : (N, 3) float64 ndarray
    error : (N,) float64 ndarray
        The quadrature's absolute error estimate, summed over the lights (where it did not converge to its
        tolerance, this says by how much); a closed form adds none (its float64 rounding, ``eps_64 / sqrt(Omega)``
        relative for a light of solid angle ``Omega``, is below it).
    """
    terms = _terms(material)
    out = np.zeros(position.shape)
    error = np.zeros(len(position))
    for light_key, twin, p, closed, _ in extended_lights(key, uniforms, np.float64, lights):
        if hasattr(twin, "exact_twin"):  # a kind whose exact closed forms are not its shader's (the environment's map)
            twin = twin.exact_twin()
        exact = [t for t in closed if twin.closed_form_is_exact(
            t.integral.form, _exponent(t, terms[t.name].values_from_uniforms(uniforms, dtype=np.float64))
            if t.integral.form != "irradiance" else None)]
        if closed_forms and hasattr(twin, "exact_lobe"):  # the mixed-material split: each term by its cheapest exact way
            value, err = _split_reflection(position, f, wo, lit, key, exact, twin, p, light_key, uniforms, terms)
            error = error + np.where(lit, err, 0.0)
        elif closed_forms and len(exact) == len(key.lit_terms):  # all in closed form (else all by quadrature: its rtol is of the sum)
            with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
                value = closed_reflection(position, f, wo, exact, twin, p, light_key, uniforms, terms, np.float64)
        else:
            value, err = _quadrature(position, f, wo, key.lit_terms, twin, p, light_key, uniforms, terms)
            error = error + np.where(lit, err, 0.0)
        out = out + np.where(lit[:, None], value, 0.0)
    return out, error


def _quadrature(position, f, wo, term_keys, twin, p, light_key, uniforms, terms):
    """The kind's float64 quadrature (``exact``) of the sum of ``term_keys``' responses: ``(value (N, 3), error
    (N,))``."""
    def integrand(index, w):
        g = f.select(index)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return terms_response(g, w, wo[index], _dot(g.n, w), term_keys, uniforms, terms, light_key.occludable)

    value, error, _ = twin.exact(position, f.n, p, integrand)
    return value, error


def _split_reflection(position, f, wo, lit, key, exact, twin, p, light_key, uniforms, terms, rtol=1e-9):
    """The mixed-material split of `exact_reflection` (issue 40), ``(value (N, 3), error (N,))``: the terms of
    irradiance form by the twin's exact irradiance (as when every term has one), the lecture's lobes by its
    ``exact_lobe`` to ``rtol`` of the rest of the pixel (`glphong.twin.environment_lobe`), and only the other terms by
    the quadrature of their sum (``exact``, its rtol of their sum)."""
    irradiance_terms = [t for t in exact if t.integral.form == "irradiance"]
    # q = 0: the twin's lobe is 1 even where r.w <= 0 (lobe_from_delta), which the quadrature integrates as it is
    lobes = [t for t in exact if t.integral.form != "irradiance"
             and _exponent(t, terms[t.name].values_from_uniforms(uniforms, dtype=np.float64)) > 0]
    rest = [t for t in key.lit_terms if t not in irradiance_terms and t not in lobes]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        value = closed_reflection(position, f, wo, irradiance_terms, twin, p, light_key, uniforms, terms, np.float64)
    error = np.zeros(len(position))
    if rest:
        more, error = _quadrature(position, f, wo, rest, twin, p, light_key, uniforms, terms)
        value = value + more
    if lobes:
        r = view_reflected(f.n, wo)
        ok = lit & np.all(np.isfinite(r), axis=1) & np.all(np.isfinite(f.n), axis=1)
        for t in lobes:
            values = terms[t.name].values_from_uniforms(uniforms, dtype=np.float64, inputs=f.inputs)
            k = np.broadcast_to(getattr(values, t.integral.scale) * occlusion_factor(t, values, light_key.occludable),
                                position.shape)
            size = np.max(np.abs(k), axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                floor = np.where(size > 0, np.max(np.abs(value), axis=1) / size, 0.0)
            lobe = np.zeros(position.shape)
            spread = np.zeros(len(position))
            q = _exponent(t, terms[t.name].values_from_uniforms(uniforms, dtype=np.float64))
            lobe[ok], spread[ok], _ = twin.exact_lobe(f.n[ok], r[ok], q, rtol, floor[ok])
            value = value + k * lobe
            error = error + size * spread
    return value, error


def terms_response(f, wi, wo, n_dot_l, term_keys, uniforms, terms, occluded=False):
    """The sum of ``term_keys``' twins (`material_response`; ``material_response_<kind>`` where they are the terms an
    extended kind samples), (N, 3); a term that does not need the view gets v = 0, as in the GLSL; ``occluded``: each
    term's times its occlusion (an occludable kind's, `occlusion_factor`)."""
    out = np.zeros(np.shape(wi), np.result_type(f.n, wi))
    for term_key in term_keys:
        term = terms[term_key.name]
        p = values_from(term, uniforms, dtype=out.dtype, inputs=f.inputs)
        response = term.response(f, wi, wo if "view" in term.needs else np.zeros_like(wi), n_dot_l, p)
        out = out + occlusion_factor(term_key, p, occluded) * response
    return out


def occlusion_factor(term_key, p, occluded):
    """The factor an occludable light's reflection takes for a term: its occlusion (a constant, or (N, 1) per
    fragment) where ``occluded`` and the key has one, else 1."""
    if not (occluded and term_key.occlusion):
        return 1.0
    value = np.asarray(getattr(p, term_key.occlusion))
    return value[..., None] if value.ndim else value


# --------------------------------------------------------------------------- mesh_fragment.glsl
def shade_inputs(scene, gbuffer, dtype=np.float64, band=None, shadows=None, only=None):
    """Per object, the fragments it covers and the inputs its program shaded them with.

    ``band`` (`glphong.checks.tolerances.BandConstants`): also the intervals of the surface inputs
    (``f.input_bounds``), for the tolerance band.  ``shadows``: the renderer's ``(shadow_map_size,
    shadow_filter_radius)`` (`glphong.Renderer.shadow_settings`), needed where a light has ``shadows=True``: each
    shadowing light's visibility is then ray-cast (``f.visibility``, `glphong.checks.shadows`).  ``only`` (H, W)
    bool: those pixels alone (a sample of the frame).

    Yields
    ------
    selection : (H, W) bool ndarray
        The object's pixels.
    obj : glphong.SceneObject
    key : glphong.shaders.key.ProgramKey
        Its radiance-program key.
    uniforms : dict of str to ndarray
        The uniforms the GPU was given, cast to ``dtype``.
    position : (N, 3) ndarray
    f : ShadingFrame
        The G-buffer normal renormalised (mesh_fragment.glsl), and the frame built from the
        G-buffer's tangent and uv where the key reads them (`shading_frame`), with the surface
        inputs from the G-buffer's uv, vertex colour and levels of detail (`material_inputs`); where the key has
        ``has_unperturbed``, ``f.unperturbed`` the frame of the G-buffer's normal before the normal map.
    n_valid : (N,) bool ndarray
    """
    height, width = gbuffer.mask.shape
    for index, obj in enumerate(scene.objects):
        selection = gbuffer.object_index == index
        if only is not None:
            selection &= only
        if not selection.any():
            continue
        key = binding(scene).program_key(obj)
        if key.shadow_slots:
            if shadows is None:
                raise ValueError("the scene has lights with shadows=True: the twin needs the renderer's shadow settings "
                                 "(shadows=renderer.shadow_settings)")
            key = replace(key, shadow_size=shadows[0], shadow_filter=shadows[1])
        uniforms = {k: uniform_as(v, dtype) for k, v in binding(scene).uniform_values(index, key, width / height).items()}
        position = gbuffer.position[selection].astype(dtype)
        n_valid, n, _ = safe_normalize(gbuffer.normal[selection].astype(dtype))
        tangent = gbuffer.tangent[selection].astype(dtype) if key.has_tangent else None
        uv = gbuffer.uv[selection].astype(dtype) if key.has_uv else None
        f = shading_frame(n, tangent, uv, key)
        unperturbed = None
        if key.has_unperturbed:  # the frame before the normal map, for a term that needs it (mesh_fragment.glsl)
            unperturbed = shading_frame(safe_normalize(gbuffer.unperturbed[selection].astype(dtype))[1], tangent, uv,
                                        key)
            f = replace(f, unperturbed=unperturbed)
        if key.inputs:
            color = gbuffer.color[selection].astype(np.float64) if key.has_color else None
            lod = gbuffer.lod[selection].astype(np.float64) if key.textured_inputs else None
            uv64 = None if uv is None else gbuffer.uv[selection].astype(np.float64)
            bounds = None
            if band is None:
                inputs = material_inputs(uv64, color, lod, key, uniforms)
            else:  # the values and their intervals from one sampling of each texture
                inputs, bounds = input_bounds(uv64, color, lod, key, uniforms, band)
            f = type(f)(f.n, f.t, f.b, f.uv, {k: v.astype(dtype) for k, v in inputs.items()}, bounds,
                        unperturbed=unperturbed)
        if key.shadow_slots:
            _, face, _ = safe_normalize(gbuffer.face[selection].astype(np.float64))  # the triangles' own normals
            f = replace(f, visibility=_visibility(scene, key, gbuffer.position[selection].astype(np.float64), face,
                                                  shadows[1], obj))
        yield selection, obj, key, uniforms, position, f, n_valid


def _visibility(scene, key, position, normal, filter_radius, receiver=None):
    """Per light of ``key`` in loop order: None, or its ray-cast visibility ``(exact, low, high)`` at the points of
    ``receiver``."""
    setups = {(s.kind, s.index): s for s in binding(scene).shadow_setups(key.lights, key.shadow_size)}
    out = []
    for light in key.lights:
        if light.extended:  # no shadows; not in incident_light's list
            continue
        for j in range(light.count):
            setup = setups.get((light.name, j))
            out.append(None if setup is None else
                       shadow_visibility(scene, setup, position, np.asarray(normal, dtype=np.float64), filter_radius,
                                         receiver))
    return tuple(out)


def shade(scene, gbuffer, dtype=np.float64, shadows=None):
    """Shade a G-buffer with the twin, fragment for fragment.

    Parameters
    ----------
    scene : glphong.Scene
    gbuffer : glphong.GBuffer
        From ``Renderer.gbuffer(scene)`` at the same image size.
    dtype : numpy dtype
        float64 (the reference) or float32 (the GPU's formulation on the CPU).
    shadows : (int, int), optional
        The renderer's shadow settings, where a light casts shadows (`shade_inputs`).

    Returns
    -------
    (H, W, 3) ndarray of ``dtype``
        Radiance [W/(m^2 sr)], 0 where not covered.
    """
    out = np.zeros(gbuffer.position.shape, dtype)
    for selection, obj, key, uniforms, position, f, n_valid in shade_inputs(scene, gbuffer, dtype, shadows=shadows):
        out[selection] = shade_point(position, f, n_valid, uniforms.get("u_eye"), key, uniforms, obj.material)
    return out
