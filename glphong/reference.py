"""The numpy twin of the GLSL shaders (DESIGN sections 1 and 3).

Every GLSL function has a twin here with the same name, the same argument order
and the same formulation; only the arithmetic is done in the dtype of the inputs
(float64 for the reference, float32 to study the GPU's formulation on the CPU).
Conventions of the mirror:

- vectors are arrays of shape ``(..., 3)``, scalars per point of shape ``(...)``;
- a GLSL function with ``out`` parameters returns ``(return value, *outs)``;
- uniforms the GLSL reads from globals are passed as the trailing ``uniforms``
  dictionary (the very float32 values the GPU was given) and the ``key``.

`shade` is the image-level entry: it shades a G-buffer, fragment for fragment.
"""
import numpy as np

__all__ = [
    "safe_normalize", "point_irradiance", "lambert", "log_one_minus", "lobe_from_delta",
    "phong_delta", "phong_lobe", "blinn_delta", "blinn_lobe", "BLINN_HALF_FLOOR", "uber_lobe",
    "incident_light", "light_response", "view_direction", "shade_point", "shade_inputs", "shade",
]

#: common.glsl FLT_MAX: vectors with a larger (or NaN) component do not normalise
FLT_MAX = float(np.finfo(np.float32).max)
#: blinn.glsl BLINN_HALF_FLOOR = 2^-20: |l + v| at or below it gives a zero Blinn lobe
BLINN_HALF_FLOOR = 2.0 ** -20


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


# --------------------------------------------------------------------------- lambert.glsl
def lambert(kd, n_dot_l):
    """E3 without E: ``kd (n.l)`` (lambert.glsl); kd (3,) [1/sr], n_dot_l (...) -> (..., 3)."""
    return kd * np.asarray(n_dot_l)[..., None]


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

    Returns 1 for q == 0, 0 for delta >= 1, else ``exp(max(q ln(1 - delta), -104))``.
    """
    delta = np.asarray(delta)
    dtype = delta.dtype if delta.dtype.kind == "f" else np.float64
    q = dtype.type(q)
    inside = delta < 1
    with np.errstate(over="ignore", invalid="ignore"):
        value = np.exp(np.maximum(q * log_one_minus(np.where(inside, delta, 0)), dtype.type(-104)))
    value = np.where(inside, value, 0)
    return np.where(q == 0, 1, value).astype(dtype)


# --------------------------------------------------------------------------- phong.glsl
def phong_delta(n, wi, wo):
    """``|r - v|^2 / 2`` with ``r = 2 (n.l) n - l`` (phong.glsl); unit (..., 3) inputs -> (...)."""
    r = 2 * _dot(n, wi)[..., None] * n - wi
    e = r - wo
    return 0.5 * _dot(e, e)


def phong_lobe(n, wi, wo, q):
    """``max(v.r, 0)^q`` (phong.glsl)."""
    return lobe_from_delta(phong_delta(n, wi, wo), q)


# --------------------------------------------------------------------------- blinn.glsl
def blinn_delta(n, wi, wo):
    """Blinn's ``delta = |h - n|^2 / 2`` (blinn.glsl).

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
    """``max(n.h, 0)^q``, 0 where `blinn_delta` is not valid (blinn.glsl)."""
    valid, delta = blinn_delta(n, wi, wo)
    return np.where(valid, lobe_from_delta(delta, q), 0).astype(delta.dtype)


# --------------------------------------------------------------------------- uber.glsl
def uber_lobe(n, wi, wo, q, lobe_kind):
    """The uber-shader's lobe (uber.glsl): Phong for ``lobe_kind == 1``, Blinn for 2, else 0.

    ``lobe_kind`` is the GLSL uniform ``u_lobe_kind``, passed explicitly.
    """
    if lobe_kind == 1:
        return phong_lobe(n, wi, wo, q)
    if lobe_kind == 2:
        return blinn_lobe(n, wi, wo, q)
    return np.zeros(np.shape(n)[:-1], np.asarray(n).dtype)


_LOBES = {"phong": phong_lobe, "blinn": blinn_lobe}


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


def light_response(n, wi, wo, n_dot_l, key, uniforms):
    """``k_d (n.l) + k_s lobe`` of one light (shade.glsl); (N, 3) in, (N, 3) out."""
    f = np.zeros_like(n)
    if key.has_diffuse:
        f = f + lambert(uniforms["u_kd"], n_dot_l)
    if key.has_specular:
        f = f + uniforms["u_ks"] * _LOBES[key.lobe](n, wi, wo, uniforms["u_q"])[..., None]
    return f


def ambient_terms(key, uniforms, shape, dtype):
    """``k_a + k_d L_a`` (the head of shade.glsl's ``shade_point``), broadcast to ``shape``."""
    radiance = np.zeros(shape, dtype)
    if key.has_ka:
        radiance = radiance + uniforms["u_ka"]
    if key.has_kd_la:
        radiance = radiance + uniforms["u_kd"] * uniforms["u_ambient"]
    return radiance


def view_direction(position, n_valid, eye, key):
    """The head of shade.glsl's light loops: ``v`` where a lobe needs it, and which points are lit.

    Returns
    -------
    wo : (N, 3) ndarray
        Unit vectors toward the eye (0 where the key has no specular lobe: not computed).
    lit : (N,) bool ndarray
        Valid normal and, where the view is needed, a valid view direction.
    """
    if not key.needs_view:
        return np.zeros_like(position), n_valid
    ok_v, wo, _ = safe_normalize(eye - position)
    return wo, n_valid & ok_v


def shade_point(position, n, n_valid, eye, key, uniforms):
    """E6 at each point (shade.glsl's ``shade_point``).

    Parameters
    ----------
    position : (N, 3) ndarray
        World-space points [m].
    n : (N, 3) ndarray
        Unit normals.
    n_valid : (N,) bool ndarray
        False where the normal was zero or not finite: ambient terms only.
    eye : (3,) ndarray or None
        Camera centre [m] (None where the key needs no view vector).
    key, uniforms
        As in `incident_light`.

    Returns
    -------
    (N, 3) ndarray
        Radiance [W/(m^2 sr)].
    """
    radiance = ambient_terms(key, uniforms, position.shape, position.dtype)
    if key.num_lights == 0:
        return radiance
    wo, lit = view_direction(position, n_valid, eye, key)
    for valid, wi, irradiance in incident_light(position, key, uniforms):
        n_dot_l = _dot(n, wi)
        gate = (lit & valid & (n_dot_l > 0))[..., None]
        with np.errstate(invalid="ignore", over="ignore"):
            term = light_response(n, wi, wo, n_dot_l, key, uniforms) * irradiance
        radiance = radiance + np.where(gate, term, 0)
    return radiance


# --------------------------------------------------------------------------- mesh_fragment.glsl
def shade_inputs(scene, gbuffer, dtype=np.float64):
    """Per object, the fragments it covers and the inputs its program shaded them with.

    Yields
    ------
    selection : (H, W) bool ndarray
        The object's pixels.
    key : glphong.key.ProgramKey
        Its radiance-program key.
    uniforms : dict of str to ndarray
        The uniforms the GPU was given, cast to ``dtype``.
    position : (N, 3) ndarray
    n : (N, 3) ndarray
        The G-buffer normal renormalised (mesh_fragment.glsl).
    n_valid : (N,) bool ndarray
    """
    height, width = gbuffer.mask.shape
    for index, obj in enumerate(scene.objects):
        selection = gbuffer.object_index == index
        if not selection.any():
            continue
        key = scene.program_key(obj)
        uniforms = {k: v.astype(dtype) for k, v in scene.uniform_values(index, key, width / height).items()}
        position = gbuffer.position[selection].astype(dtype)
        n_valid, n, _ = safe_normalize(gbuffer.normal[selection].astype(dtype))
        yield selection, key, uniforms, position, n, n_valid


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
    for selection, key, uniforms, position, n, n_valid in shade_inputs(scene, gbuffer, dtype):
        out[selection] = shade_point(position, n, n_valid, uniforms.get("u_eye"), key, uniforms)
    return out
