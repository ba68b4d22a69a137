"""A material's response on direction pairs, on the GPU or by its twin, without a scene (`evaluate`: a vertex
program captured by transform feedback), and its parts for the tolerance check (`response_inputs`, `twin_response`,
`gpu_response`).  `glphong.testing` re-exports `evaluate`; `glphong.analysis` evaluates BRDFs through it.
"""
import threading

import numpy as np

from glphong.checks import reference as ref
from glphong.definitions.material import Material
from glphong.definitions.table import uniform_as
from glphong.gpu.programs import ProgramCache
from glphong.shaders.builders import response_key
from glphong.evaluation.pool import pooled

__all__ = ["evaluate", "response_inputs", "twin_response", "gpu_response"]


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


def response_inputs(material, wi, wo, normal=(0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0), uv=None):
    """The float32 inputs both sides evaluate: unit directions (normalised in float64, then rounded).

    Parameters
    ----------
    material : glphong.materials.Material
    wi, wo, normal, tangent, uv
        As in `evaluate`.

    Returns
    -------
    wi, wo, normal : (N, 3) float32 ndarray
    tangent : (N, 4) float32 ndarray
        Handedness in the fourth component.
    uv : (N, 2) float32 ndarray
    """
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


def twin_response(material, key, uniforms, wi, wo, normal, tangent, uv):
    """The numpy twin's response in float64 on the float32 inputs of `response_inputs`, and what the tolerance
    band of `glphong.checks.tolerances.response_band` is computed from.

    Parameters
    ----------
    material : glphong.materials.Material
    key : glphong.shaders.keys.ProgramKey
        ``glphong.shaders.builders.response_key(material)``.
    uniforms : dict of str to array_like
        ``material.uniform_values(key)``.
    wi, wo, normal, tangent, uv : ndarray
        From `response_inputs`.

    Returns
    -------
    response : (N, 3) float64 ndarray
        0 where ``n.wi <= 0``.
    frame : glphong.materials.ShadingFrame
        The twin's shading frame at every row.
    wi, wo : (N, 3) float64 ndarray
    n_dot_l : (N,) float64 ndarray
    uniforms : dict of str to ndarray
        ``uniforms`` in float64.
    """
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
    wi, wo, normal, tangent, uv = response_inputs(material, wi, wo, normal, tangent, uv)
    key = response_key(material)
    uniforms = material.uniform_values(key)
    if twin:
        return twin_response(material, key, uniforms, wi, wo, normal, tangent, uv)[0]
    return gpu_response(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context)


def gpu_response(material, key, uniforms, wi, wo, normal, tangent, uv, backend="auto", context=None):
    """The GLSL ``material_response()`` on the GPU at the float32 inputs of `response_inputs` (see `evaluate`).

    Parameters
    ----------
    material : glphong.materials.Material
        Named in a GL error's message.
    key, uniforms
        As in `twin_response`.
    wi, wo, normal, tangent, uv : ndarray
        From `response_inputs`.
    backend, context
        As in `evaluate`: the backend's pooled context (`glphong.evaluation.pool.pooled`) unless ``context`` is given.

    Returns
    -------
    (N, 3) float32 ndarray
    """
    import moderngl

    count = len(wi)
    if count == 0 or not key.terms:
        return np.zeros((count, 3), np.float32)
    if context is None:
        gl, programs, lock = pooled(backend)
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
