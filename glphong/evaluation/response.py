"""Evaluating a material's response on direction pairs, on the GPU or by its twin, without a scene
(`evaluate`: a vertex program captured by transform feedback), and the direction sets, frames and float32
unit vectors the checks use.  `glphong.testing` re-exports all of it for tests; `glphong.analysis`
evaluates BRDFs through it.
"""
import atexit
import threading

import numpy as np

from glphong.checks import reference as ref
from glphong.checks.tolerances import EPS
from glphong.gpu.contexts import EGLDisplayTerminatedError, create_context
from glphong.gpu.programs import ProgramCache
from glphong.materials.model import Material
from glphong.materials.table import uniform_as
from glphong.shaders.builders import response_key

__all__ = ["evaluate", "direction_sets", "frame_around", "direction", "rotate_toward", "float32_units",
           "cosine_power_interval"]


_POOL = {}
_POOL_LOCK = threading.Lock()


def _pooled(backend):
    """A context and its program cache per backend, created on first use and kept until exit."""

    with _POOL_LOCK:
        entry = _POOL.get(backend)
        if entry is not None:
            try:
                with entry[2], entry[0]:
                    pass
            except EGLDisplayTerminatedError:  # its display was terminated (pyrender on EGL): start anew
                entry[0]._released = True
                entry = None
        if entry is None or entry[0].mgl is None:
            gl = create_context(backend)
            gl.detach()  # entered per call, from any thread
            entry = _POOL[backend] = (gl, ProgramCache(gl.mgl), threading.RLock())
        return entry


@atexit.register
def _release_pool():
    for gl, programs, _ in _POOL.values():
        try:
            with gl:
                programs.release()
            gl.release()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass
    _POOL.clear()


def _rows(name, value, count, width):
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 1:
        a = np.broadcast_to(a, (count, a.shape[0]))
    if a.ndim != 2 or a.shape != (count, width):
        raise ValueError(f"{name} must have shape ({width},) or ({count}, {width}) (got {np.shape(value)})")
    return a


def _unit_rows(name, value, count):
    a = _rows(name, value, count, 3)
    length = np.linalg.norm(a, axis=1, keepdims=True)
    if not np.all(np.isfinite(a)) or np.any(length == 0):
        raise ValueError(f"{name} must be finite, non-zero 3-vectors")
    return a / length


def _inputs(material, wi, wo, normal, tangent, uv):
    """The float32 inputs both sides evaluate: unit directions (normalised in float64, rounded)."""
    if not isinstance(material, Material):
        raise TypeError(f"material must be a glphong material (got {type(material).__name__})")
    wi = np.asarray(wi, dtype=np.float64)
    if wi.ndim != 2 or wi.shape[1] != 3:
        raise ValueError(f"wi must have shape (N, 3) (got {wi.shape})")
    count = len(wi)
    f32 = lambda a: np.ascontiguousarray(a, dtype=np.float32)  # noqa: E731
    tangent = _rows("tangent", tangent, count, np.shape(tangent)[-1] if np.ndim(tangent) else 3)
    if tangent.shape[1] == 3:
        tangent = np.concatenate([tangent, np.ones((count, 1))], axis=1)
    elif tangent.shape[1] != 4:
        raise ValueError(f"tangent must have 3 or 4 components (got {tangent.shape[1]})")
    return (f32(_unit_rows("wi", wi, count)), f32(_unit_rows("wo", wo, count)), f32(_unit_rows("normal", normal, count)),
            f32(tangent), f32(_rows("uv", (0.0, 0.0) if uv is None else uv, count, 2)))


def _twin(material, key, uniforms, wi, wo, normal, tangent, uv):
    u = {k: uniform_as(v, np.float64) for k, v in uniforms.items()}
    f = ref.shading_frame(normal.astype(np.float64), tangent.astype(np.float64), uv.astype(np.float64), key)
    wi64, wo64 = wi.astype(np.float64), wo.astype(np.float64)
    n_dot_l = np.sum(f.n * wi64, axis=-1)
    out = np.zeros(wi.shape)
    gate = n_dot_l > 0
    if gate.any():
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            out[gate] = ref.material_response(f.select(gate), wi64[gate], wo64[gate], n_dot_l[gate], key, u, material)
    return out, f, wi64, wo64, n_dot_l, u


def evaluate(material, wi, wo, normal=(0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0), backend="auto", twin=False,
             uv=None, context=None):
    """A material's response ``f_r(wi, wo) (n.wi)`` [1/sr] at direction pairs, on the GPU or by its twin.

    The GLSL ``material_response()`` (the sum of the material's non-vanishing terms) runs once per
    row in a vertex program captured by transform feedback: no scene, no light, no rasterisation.
    Rows where ``n.wi <= 0`` give 0 (the light loop never evaluates them).

    Parameters
    ----------
    material : glphong.materials.Material
    wi, wo : (N, 3) array_like
        Directions toward the light and the viewer (normalised here in float64, then rounded to
        float32: both sides see the same float32 unit vectors).
    normal : (3,) or (N, 3) array_like
        Surface normal (normalised likewise).
    tangent : (3,), (4,), (N, 3) or (N, 4) array_like
        Raw tangent, handedness in the fourth component (default +1); orthonormalised against the
        normal as the shader does (only read by terms that need ``'tangent'``).
    backend : {'auto', 'egl', 'osmesa'}
        A context per backend is created on first use and kept for the process.
    twin : bool
        Return the numpy twin in float64 on the same float32 inputs instead of the GPU.
    uv : (2,) or (N, 2) array_like, optional
        Texture coordinates (for terms that need ``'uv'``).
    context : glphong.gpu.contexts.GLContext, optional
        Use this context instead of the pooled one.

    Returns
    -------
    (N, 3) ndarray
        float32 from the GPU, float64 from the twin.
    """
    wi, wo, normal, tangent, uv = _inputs(material, wi, wo, normal, tangent, uv)
    key = response_key(material)
    uniforms = material.uniform_values(key)
    if twin:
        return _twin(material, key, uniforms, wi, wo, normal, tangent, uv)[0]
    return _gpu(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context)


def _gpu(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context):
    import moderngl

    count = len(wi)
    if count == 0 or not key.terms:
        return np.zeros((count, 3), np.float32)
    if context is None:
        gl, programs, lock = _pooled(backend)
    else:
        gl, programs, lock = context, ProgramCache(context.mgl), threading.RLock()
    columns = {"in_wi": (wi, "3f"), "in_wo": (wo, "3f"), "in_normal": (normal, "3f")}
    if key.has_tangent:
        columns["in_tangent"] = (tangent, "4f")
    if key.has_uv:
        columns["in_uv"] = (uv, "2f")
    mgl = gl.mgl
    with lock, gl:  # one evaluation at a time on a pooled context, from any thread
        program = programs.get(key)
        program.bind(uniforms)
        buffers = {name: mgl.buffer(data.tobytes()) for name, (data, _) in columns.items()}
        result = mgl.buffer(reserve=count * 12)
        content = [(buffers[name], fmt, name) for name, (_, fmt) in columns.items() if name in program.gl_program]
        vao = mgl.vertex_array(program.gl_program, content)
        try:
            gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.float32).reshape(count, 3).copy()
            gl.check_error(f"evaluate of {material!r}")
        finally:
            for obj in (vao, result, *buffers.values()):
                obj.release()
            if context is not None:
                programs.release()
    return data


def _rotate_toward(v, axis, angle):
    """Rotate unit rows ``v`` by ``angle`` [rad] toward the unit rows ``axis`` (perpendicular to v)."""
    return np.cos(angle)[..., None] * v + np.sin(angle)[..., None] * axis


def direction_sets(n=2000, seed=0):
    """Direction pairs that exercise a BRDF: seeded random, and the edges where shaders break.

    With the normal +z: random ``wi``, ``wo`` over the upper hemisphere (and some ``wo`` below it),
    and the edge sets: grazing light (``n.l`` from 1e-2 down to 1e-7, and 0), grazing view, the mirror
    direction (the peak of Phong and Blinn lobes) and small offsets from it, ``l = v`` (the
    retro-reflection peak), ``l = -v`` mirrored at grazing, ``n.l`` just above 0, and light and view
    both so grazing (cosines 1e-30 to 1e-19) that ``(n.l)(n.v)`` is below FLT_MIN.

    Parameters
    ----------
    n : int
        Number of random pairs (the edge sets come on top, about 40 % more).
    seed : int

    Returns
    -------
    wi, wo : (M, 3) float64 ndarray
        Unit vectors.
    labels : (M,) ndarray of str
        Which set each pair belongs to.
    """
    rng = np.random.default_rng(seed)

    def hemisphere(count, lower=False):
        v = rng.normal(size=(count, 3))
        v[:, 2] = np.abs(v[:, 2]) * (-1.0 if lower else 1.0)
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    def at(cos_theta, count):
        phi = rng.uniform(0, 2 * np.pi, count)
        s = np.sqrt(np.maximum(1.0 - cos_theta ** 2, 0.0))
        return np.stack([s * np.cos(phi), s * np.sin(phi), np.broadcast_to(cos_theta, (count,))], axis=1)

    def mirror(wi):
        return wi * np.array([-1.0, -1.0, 1.0])

    sets = []
    k = max(n // 20, 8)
    sets.append(("random", hemisphere(n), hemisphere(n)))
    sets.append(("view below the surface", hemisphere(k), hemisphere(k, lower=True)))
    for cosine in (1e-2, 1e-4, 1e-6, 1e-7, 0.0):
        sets.append((f"grazing light n.l={cosine:g}", at(np.full(k, cosine), k), hemisphere(k)))
    for cosine in (1e-2, 1e-4, 1e-6):
        sets.append((f"grazing view n.v={cosine:g}", hemisphere(k), at(np.full(k, cosine), k)))
    wi = hemisphere(4 * k)
    sets.append(("mirror direction (lobe peak)", wi, mirror(wi)))
    for offset in (1e-6, 1e-4, 1e-3, 1e-2, 1e-1):
        wi = hemisphere(k)
        peak = mirror(wi)
        axis = np.cross(peak, rng.normal(size=(k, 3)))
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        sets.append((f"near the mirror direction, {offset:g} rad", wi, _rotate_toward(peak, axis, np.full(k, offset))))
    wi = hemisphere(2 * k)
    sets.append(("l = v (retro-reflection)", wi, wi.copy()))
    wi = at(np.full(k, 3e-6), k)
    sets.append(("l, v grazing and mirrored", wi, -wi * np.array([1.0, 1.0, -1.0])))
    wi = at(10.0 ** rng.uniform(-7, -3, k), k)
    sets.append(("n.l just above 0", wi, mirror(wi)))
    wi, wo = at(10.0 ** rng.uniform(-30, -19, k), k), at(10.0 ** rng.uniform(-30, -19, k), k)
    sets.append(("l and v grazing, (n.l)(n.v) below FLT_MIN", wi, wo))
    labels = np.concatenate([[label] * len(a) for label, a, _ in sets])
    return np.concatenate([a for _, a, _ in sets]), np.concatenate([b for _, _, b in sets]), labels


# --------------------------------------------------------------------------- closed-form helpers
def frame_around(n):
    """An orthonormal ``(t, b)`` completing the unit normal ``n`` (3,): ``(t, b, n)`` right-handed."""
    n = np.asarray(n, dtype=np.float64)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(n, helper)
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def direction(n, theta, phi):
    """The unit vector at polar angle ``theta`` [rad] from the unit ``n`` and azimuth ``phi`` [rad] about it
    (measured from `frame_around`'s ``t``)."""
    t, b = frame_around(n)
    return np.sin(theta) * (np.cos(phi) * t + np.sin(phi) * b) + np.cos(theta) * np.asarray(n, dtype=np.float64)


def rotate_toward(a, target, angle):
    """Unit ``a`` (3,) rotated by ``angle`` [rad] toward ``target``, in their plane."""
    axis = target - np.dot(target, a) * a
    axis /= np.linalg.norm(axis)
    return np.cos(angle) * a + np.sin(angle) * axis


def float32_units(v):
    """Rows of ``v`` normalised in float64 and rounded to float32 (returned as float64): exactly the unit
    vectors `evaluate` hands to the GPU and to the twin."""
    v = np.asarray(v, dtype=np.float64)
    return np.asarray(v / np.linalg.norm(v, axis=-1, keepdims=True), dtype=np.float32).astype(np.float64)


def cosine_power_interval(cos_alpha, q, spread):
    """The interval of float32 values consistent with ``cos(alpha)^q``, for closed-form tests of lobes.

    ``alpha`` is the angle from the lobe's peak; float32 inputs and arithmetic leave it uncertain by
    ``+- spread`` [rad] (a few eps: the caller states it for its lobe); ``exp`` is good to
    ``(3 + 2|x|)`` ulp (GLSL 4.50, 4.7.1) and ``ln(1 - delta)`` to a few ulp relative, so the value is
    widened by ``eps (8 + 12 lambda)`` relative, ``lambda = -ln(value)``.  The caller accepts 0 below
    FLT_MIN (flush to zero).

    Returns
    -------
    low, high : ndarray
    """
    alpha = np.arccos(np.clip(cos_alpha, -1.0, 1.0))
    low = np.cos(np.minimum(alpha + spread, np.pi / 2)) ** q
    high = np.cos(np.maximum(alpha - spread, 0.0)) ** q
    lam = -np.log(np.maximum(low, 1e-300))
    return low * (1 - EPS * (8 + 12 * lam)), high * (1 + EPS * (8 + 12 * lam))
