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
import numpy as np

from .materials.table import uniform_as

__all__ = [
    "safe_normalize", "frame_from_tangent", "shading_frame", "point_irradiance", "log_one_minus", "lobe_from_delta",
    "phong_delta", "phong_lobe", "BLINN_HALF_FLOOR", "blinn_delta", "blinn_lobe", "half_cosine",
    "fresnel_schlick", "fresnel_dielectric", "atan2_first_quadrant", "incident_light", "material_emission", "material_response", "light_term", "view_direction", "shade_point",
    "shade_inputs", "shade",
]

def __getattr__(name):
    """A model's twin function by name (``reference.lambert``): each lives with its model in
    ``glphong.materials.<module>``; this finds it in the modules of the registered models."""
    import sys

    from .materials import registered_models

    for model in registered_models():
        module = sys.modules.get(model.__module__)
        if name in getattr(module, "__all__", ()):
            return getattr(module, name)
    raise AttributeError(f"module 'glphong.reference' has no attribute {name!r}")


#: common.glsl FLT_MAX: vectors with a larger (or NaN) component do not normalise
FLT_MAX = float(np.finfo(np.float32).max)
#: common.glsl FRAME_PARALLEL_LIMIT (2^-10): a tangent whose part across n is at most this times its
#: part along n counts as parallel to n in `frame_from_tangent`
FRAME_PARALLEL_LIMIT = 2.0 ** -10


def _dot(a, b):
    return np.sum(a * b, axis=-1)


# --------------------------------------------------------------------------- common.glsl
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
    s = np.max(np.abs(x), axis=-1)
    valid = (s > 0) & (s <= FLT_MAX)
    s_safe = np.where(valid, s, 1).astype(x.dtype)[..., None]
    with np.errstate(invalid="ignore", over="ignore"):
        y = np.where(valid[..., None], x / s_safe, 0).astype(x.dtype)
        yy = np.where(valid, _dot(y, y), 1).astype(x.dtype)
        length = np.where(valid, s_safe[..., 0] * np.sqrt(yy), 0).astype(x.dtype)
        x_hat = (y * (1 / np.sqrt(yy))[..., None]).astype(x.dtype)  # y * inversesqrt(y.y), as in GLSL
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
    s = np.where(n[..., 2] >= 0, 1.0, -1.0).astype(n.dtype)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = -1.0 / (s + n[..., 2])
        fallback = np.stack([1.0 + s * n[..., 0] * n[..., 0] * a, s * n[..., 0] * n[..., 1] * a, -s * n[..., 0]], axis=-1)
    t = np.where(projected[..., None], t, fallback).astype(n.dtype)
    b = (np.where(tangent[..., 3] < 0, -1.0, 1.0)[..., None] * np.cross(n, t)).astype(n.dtype)
    return t, b


def shading_frame(n, tangent=None, uv=None, key=None):
    """The `ShadingFrame` of shading points (common.glsl ``shading_frame``): ``t``, ``b`` from
    `frame_from_tangent` where ``key.has_tangent``; ``uv`` where ``key.has_uv``."""
    from .materials.model import ShadingFrame

    if key is not None and key.has_tangent:
        t, b = frame_from_tangent(n, tangent)
        return ShadingFrame(n, t, b, uv if key.has_uv else None)
    return ShadingFrame(n, None, None, uv if key is not None and key.has_uv else None)


# --------------------------------------------------------------------------- lights.glsl
def point_irradiance(intensity, d):
    """E1 as ``min((I / d) / d, FLT_MAX)`` (lights.glsl).

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
    with np.errstate(over="ignore", under="ignore"):
        return np.minimum((intensity / d) / d, FLT_MAX)


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


def log_one_minus(delta):
    """``ln(1 - delta)`` for ``0 <= delta < 1`` (lobe.glsl).

    ``-2 artanh(delta / (2 - delta))`` by its odd series for ``delta < 1/2`` (8 terms in
    float32 as in the GLSL, as many as float64 needs otherwise), ``log(1 - delta)`` above.
    """
    delta = np.asarray(delta)
    dtype = delta.dtype if delta.dtype.kind == "f" else np.float64
    delta = delta.astype(dtype)
    small = delta < 0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        two_sigma = np.where(small, (2 * delta) / (2 - delta), 0).astype(dtype)
        t = (0.25 * (two_sigma * two_sigma)).astype(dtype)
        series = np.zeros_like(two_sigma)
        for k in reversed(range(_series_terms(dtype))):
            series = (series * t + dtype.type(1.0) / dtype.type(2 * k + 1)).astype(dtype)
        direct = np.log(np.where(small, 0.5, 1 - delta)).astype(dtype)
    return np.where(small, -two_sigma * series, direct).astype(dtype)


def lobe_from_delta(delta, q):
    """``(1 - delta)^q``, stable for q up to FLT_MAX (lobe.glsl).

    Returns 1 for q == 0, 0 for delta >= 1, else ``exp(max(q ln(1 - delta), -104))``; ``q`` a scalar or
    an array broadcasting with ``delta`` (a per-point exponent).
    """
    delta = np.asarray(delta)
    dtype = delta.dtype if delta.dtype.kind == "f" else np.float64
    q = np.asarray(q, dtype=dtype)
    inside = delta < 1
    with np.errstate(over="ignore", invalid="ignore"):
        value = np.exp(np.maximum(q * log_one_minus(np.where(inside, delta, 0)), dtype.type(-104)))
    value = np.where(inside, value, 0)
    return np.where(q == 0, 1, value).astype(dtype)


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
    return valid, np.where(valid, 0.5 * _dot(e, e), 2).astype(e.dtype)


def blinn_lobe(n, wi, wo, q):
    """``max(n.h, 0)^q``, 0 where `blinn_delta` is not valid (lobe.glsl); (...)."""
    valid, delta = blinn_delta(n, wi, wo)
    return np.where(valid, lobe_from_delta(delta, q), 0).astype(delta.dtype)


def half_cosine(wi, wo):
    """``h.l`` with ``h = (l + v)/|l + v|``, 0 where ``l + v`` does not normalise (lobe.glsl); (...)."""
    ok, h, _ = safe_normalize(wi + wo)
    return np.where(ok, _dot(h, wi), 0).astype(h.dtype)


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
    return np.where((g2 < 0) | (g_plus_c <= 0), 1, np.minimum(f, 1)).astype(dtype)


# --------------------------------------------------------------------------- angle.glsl
def atan2_first_quadrant(y, x):
    """``atan(y / x)`` [rad] in [0, pi/2] for ``y, x >= 0``, 0 where both are 0 (angle.glsl): exact here
    (``numpy.arctan2``); the GLSL evaluates Cephes' atanf polynomial, good to 3 ulp (GLSL's own atan
    is not: 2e-5 relative measured on llvmpipe).  (...) -> (...)."""
    return np.arctan2(y, x)


# --------------------------------------------------------------------------- shade.glsl
def incident_light(position, key, uniforms):
    """Direction and irradiance of every light at each point: the head of shade.glsl's loops.

    Parameters
    ----------
    position : (N, 3) ndarray
        World-space points [m].
    key : glphong.key.ProgramKey
    uniforms : dict of str to ndarray
        The program's uniforms, in the dtype of the computation.

    Returns
    -------
    list of (valid, wi, irradiance)
        Per light, in shader order: ``valid`` (N,) bool (the direction normalised),
        ``wi`` (N, 3) unit vector toward the light, ``irradiance`` (N, 3) E [W/m^2].
    """
    out = []
    for j in range(key.num_point_lights):
        valid, wi, d = safe_normalize(uniforms["u_point_position"][j] - position)
        with np.errstate(divide="ignore", invalid="ignore"):
            out.append((valid, wi, point_irradiance(uniforms["u_point_intensity"][j], d)))
    for j in range(key.num_unattenuated_lights):
        valid, wi, _ = safe_normalize(uniforms["u_unattenuated_position"][j] - position)
        out.append((valid, wi, np.broadcast_to(uniforms["u_unattenuated_radiance"][j], position.shape)))
    for j in range(key.num_directional_lights):
        wi = np.broadcast_to(uniforms["u_directional_direction"][j], position.shape)
        out.append((np.ones(len(position), bool), wi, np.broadcast_to(uniforms["u_directional_irradiance"][j], position.shape)))
    return out


def _terms(material):
    return {term.name: term for term in material.components}


def material_emission(key, uniforms, shape, dtype, material=None, inputs=None):
    """``k_a + sum_terms k L_a`` (the generated material chunk's ``material_emission``), broadcast to ``shape``;
    ``inputs`` the per-fragment values of surface inputs (`material_inputs`), where the key has them."""
    radiance = np.zeros(shape, dtype)
    if key.has_ka:
        radiance = radiance + uniforms["u_ka"]
    for term in key.terms:
        if term.ambient:
            scale = np.float32(term.ambient_scale).astype(dtype)
            name = f"u_{term.name}_{term.ambient_param}"
            k = inputs[name] if inputs is not None and name in inputs else uniforms[name]
            radiance = radiance + k * (scale * uniforms["u_ambient"])
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
        The level of detail of each textured input, in `ProgramKey.textured_inputs` order.
    key : glphong.key.ProgramKey
    uniforms : dict
        The program's uniforms (``u_<model>_<param>_scale`` and ``_texture``).
    sample : callable, optional
        ``sample(image, uv, lod)`` in place of `surface_texture`; it may return ``(k, N, 3)`` (several
        arrays that the products broadcast over: `glphong.tolerances.input_bounds` passes the value and
        its interval from one sampling).

    Returns
    -------
    dict of str to (N, 3) (or (k, N, 3)) float64 ndarray
        By uniform name; empty where the key has no surface input.
    """
    from .materials.surface import surface_texture

    sample = surface_texture if sample is None else sample
    out = {}
    textured = list(key.textured_inputs)
    for term, param, mode in key.inputs:
        name = f"u_{term}_{param}"
        value = np.asarray(uniforms[f"{name}_scale"], dtype=np.float64)
        if "texture" in mode:
            value = value * sample(uniforms[f"{name}_texture"], uv, lod[:, textured.index((term, param))])
        if "vertex" in mode:
            value = value * color
        n = len(uv) if uv is not None else len(color)
        out[name] = np.broadcast_to(value, np.broadcast_shapes(np.shape(value), (n, 3)))
    return out


def material_response(f, wi, wo, n_dot_l, key, uniforms, material):
    """Sum of the lit terms' twins (the generated material chunk's ``material_response``); (N, 3)."""
    terms = _terms(material)
    out = np.zeros(np.shape(wi), np.result_type(f.n, wi))
    for term_key in key.lit_terms:  # a term that does not need the view gets v = 0, as in the GLSL
        term = terms[term_key.name]
        p = term.values_from_uniforms(uniforms, dtype=out.dtype, inputs=f.inputs)
        view = wo if "view" in term.needs else np.zeros_like(wi)
        out = out + term.response(f, wi, view, n_dot_l, p)
    return out


def light_term(response, irradiance):
    """``response * E``, exactly 0 where ``E = 0`` (shade.glsl): an overflowed response never makes NaN."""
    with np.errstate(invalid="ignore", over="ignore"):
        return np.where(irradiance == 0, 0.0, response * irradiance).astype(np.result_type(response, irradiance))


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


def shade_point(position, n, n_valid, eye, key, uniforms, material):
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

    Returns
    -------
    (N, 3) ndarray
        Radiance [W/(m^2 sr)].
    """
    f = n if hasattr(n, "n") else shading_frame(np.asarray(n), key=key)
    radiance = material_emission(key, uniforms, position.shape, position.dtype, material, f.inputs)
    if key.num_lights == 0:
        return radiance
    wo, lit = view_direction(position, n_valid, eye, key)
    for valid, wi, irradiance in incident_light(position, key, uniforms):
        n_dot_l = _dot(f.n, wi)
        gate = lit & valid & (n_dot_l > 0)
        term = np.zeros_like(radiance)
        if gate.any():
            g = f.select(gate)
            with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
                term[gate] = light_term(material_response(g, wi[gate], wo[gate], n_dot_l[gate], key, uniforms, material),
                                        irradiance[gate])
        radiance = radiance + term
    return radiance


# --------------------------------------------------------------------------- mesh_fragment.glsl
def shade_inputs(scene, gbuffer, dtype=np.float64, band=None):
    """Per object, the fragments it covers and the inputs its program shaded them with.

    ``band`` (`glphong.tolerances.BandConstants`): also the intervals of the surface inputs
    (``f.input_bounds``), for the tolerance band.

    Yields
    ------
    selection : (H, W) bool ndarray
        The object's pixels.
    obj : glphong.SceneObject
    key : glphong.key.ProgramKey
        Its radiance-program key.
    uniforms : dict of str to ndarray
        The uniforms the GPU was given, cast to ``dtype``.
    position : (N, 3) ndarray
    f : ShadingFrame
        The G-buffer normal renormalised (mesh_fragment.glsl), and the frame built from the
        G-buffer's tangent and uv where the key reads them (`shading_frame`), with the surface
        inputs from the G-buffer's uv, vertex colour and levels of detail (`material_inputs`).
    n_valid : (N,) bool ndarray
    """
    height, width = gbuffer.mask.shape
    for index, obj in enumerate(scene.objects):
        selection = gbuffer.object_index == index
        if not selection.any():
            continue
        key = scene.program_key(obj)
        uniforms = {k: uniform_as(v, dtype) for k, v in scene.uniform_values(index, key, width / height).items()}
        position = gbuffer.position[selection].astype(dtype)
        n_valid, n, _ = safe_normalize(gbuffer.normal[selection].astype(dtype))
        tangent = gbuffer.tangent[selection].astype(dtype) if key.has_tangent else None
        uv = gbuffer.uv[selection].astype(dtype) if key.has_uv else None
        f = shading_frame(n, tangent, uv, key)
        if key.inputs:
            color = gbuffer.color[selection].astype(np.float64) if key.has_color else None
            lod = gbuffer.lod[selection].astype(np.float64) if key.textured_inputs else None
            uv64 = None if uv is None else gbuffer.uv[selection].astype(np.float64)
            bounds = None
            if band is None:
                inputs = material_inputs(uv64, color, lod, key, uniforms)
            else:  # the values and their intervals from one sampling of each texture
                from .tolerances import input_bounds

                inputs, bounds = input_bounds(uv64, color, lod, key, uniforms, band)
            f = type(f)(f.n, f.t, f.b, f.uv, {k: v.astype(dtype) for k, v in inputs.items()}, bounds)
        yield selection, obj, key, uniforms, position, f, n_valid


def shade(scene, gbuffer, dtype=np.float64):
    """Shade a G-buffer with the twin, fragment for fragment.

    Parameters
    ----------
    scene : glphong.Scene
    gbuffer : glphong.GBuffer
        From ``Renderer.gbuffer(scene)`` at the same image size.
    dtype : numpy dtype
        float64 (the reference) or float32 (the GPU's formulation on the CPU).

    Returns
    -------
    (H, W, 3) ndarray of ``dtype``
        Radiance [W/(m^2 sr)], 0 where not covered.
    """
    out = np.zeros(gbuffer.position.shape, dtype)
    for selection, obj, key, uniforms, position, f, n_valid in shade_inputs(scene, gbuffer, dtype):
        out[selection] = shade_point(position, f, n_valid, uniforms.get("u_eye"), key, uniforms, obj.material)
    return out
