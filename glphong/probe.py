"""Evaluate single GLSL functions on the GPU, one input row per vertex, via transform feedback.

This is how each GLSL chunk function is tested against its numpy twin of the same
name (DESIGN section 7, layer 1): the function is called from a generated vertex
shader on float32 inputs and its return value and ``out`` parameters are captured.

Example
-------
>>> with glphong.create_context("egl") as gl:                               # doctest: +SKIP
...     out = probe.evaluate(gl, "lobe_from_delta", delta=[0.0, 1e-6], q=[1e6, 1e6])
...     out["return"]
"""
from dataclasses import dataclass

import moderngl
import numpy as np

from .programs import GLSL_VERSION, chunk_source

__all__ = ["Signature", "SIGNATURES", "evaluate", "shade_points"]

_WIDTH = {"float": 1, "vec3": 3, "bool": 1}


@dataclass(frozen=True)
class Signature:
    """A GLSL function's parameters and the chunks that define it.

    Attributes
    ----------
    chunks : tuple of str
        Chunk files to include, in order.
    inputs : tuple of (str, str)
        ``(name, glsl type)`` of the ``in`` parameters, in order.
    outputs : tuple of (str, str)
        ``(name, glsl type)`` of the ``out`` parameters, in order.
    returns : str
        GLSL return type.
    """

    chunks: tuple
    inputs: tuple
    outputs: tuple
    returns: str


_N_WI_WO = (("n", "vec3"), ("wi", "vec3"), ("wo", "vec3"))

#: every pure chunk function, by name (its numpy twin in glphong.reference has the same name)
SIGNATURES = {
    "safe_normalize": Signature(("common",), (("x", "vec3"),), (("x_hat", "vec3"), ("length", "float")), "bool"),
    "point_irradiance": Signature(("lights",), (("intensity", "vec3"), ("d", "float")), (), "vec3"),
    "lambert": Signature(("lambert",), (("kd", "vec3"), ("n_dot_l", "float")), (), "vec3"),
    "log_one_minus": Signature(("lobe",), (("delta", "float"),), (), "float"),
    "lobe_from_delta": Signature(("lobe",), (("delta", "float"), ("q", "float")), (), "float"),
    "phong_delta": Signature(("lobe", "phong"), _N_WI_WO, (), "float"),
    "phong_lobe": Signature(("lobe", "phong"), _N_WI_WO + (("q", "float"),), (), "float"),
    "blinn_delta": Signature(("common", "lobe", "blinn"), _N_WI_WO, (("delta", "float"),), "bool"),
    "blinn_lobe": Signature(("common", "lobe", "blinn"), _N_WI_WO + (("q", "float"),), (), "float"),
}


def probe_source(name, signature):
    """The vertex shader that calls ``name`` once per vertex and exports its results."""
    lines = [GLSL_VERSION]
    lines += [chunk_source(c) for c in signature.chunks]
    lines += [f"in {t} in_{p};" for p, t in signature.inputs]
    exported = (("return", signature.returns),) + signature.outputs
    lines += [f"out {'float' if t == 'bool' else t} out_{p};" for p, t in exported]
    lines.append("void main() {")
    lines += [f"    {t} local_{p};" for p, t in signature.outputs]
    args = [f"in_{p}" for p, _ in signature.inputs] + [f"local_{p}" for p, _ in signature.outputs]
    lines.append(f"    {signature.returns} result = {name}({', '.join(args)});")
    lines.append("    out_return = " + ("result ? 1.0 : 0.0;" if signature.returns == "bool" else "result;"))
    lines += [f"    out_{p} = local_{p};" for p, _ in signature.outputs]
    lines.append("}")
    return "\n".join(lines) + "\n"


def evaluate(gl, name, **inputs):
    """Call GLSL function ``name`` on rows of float32 inputs.

    Parameters
    ----------
    gl : glphong.contexts.GLContext
    name : str
        A key of `SIGNATURES`.
    **inputs : array_like
        One array per ``in`` parameter: shape ``(N,)`` for float, ``(N, 3)`` for vec3;
        scalars broadcast.  Cast to float32.

    Returns
    -------
    dict of str to ndarray
        ``'return'`` and each ``out`` parameter, float32 (bool as ``bool``), shape ``(N,)`` or ``(N, 3)``.
    """
    signature = SIGNATURES[name]
    names = [p for p, _ in signature.inputs]
    if sorted(inputs) != sorted(names):
        raise TypeError(f"{name} takes inputs {names} (got {sorted(inputs)})")
    columns = [np.asarray(inputs[p], dtype=np.float32) for p in names]
    count = max(c.shape[0] if c.ndim and (c.ndim == 2 or _WIDTH[t] == 1) else 1
                for c, (_, t) in zip(columns, signature.inputs))
    columns = [np.ascontiguousarray(np.broadcast_to(c, (count, _WIDTH[t]) if _WIDTH[t] == 3 else (count,)))
               for c, (_, t) in zip(columns, signature.inputs)]
    exported = (("return", signature.returns),) + signature.outputs
    mgl = gl.mgl
    with gl:
        program = mgl.program(vertex_shader=probe_source(name, signature), varyings=[f"out_{p}" for p, _ in exported])
        buffers = [mgl.buffer(c.tobytes()) for c in columns]
        stride = sum(_WIDTH[t] for _, t in exported)
        result = mgl.buffer(reserve=count * stride * 4)
        vao = mgl.vertex_array(program, [(b, f"{_WIDTH[t]}f", f"in_{p}") for b, (p, t) in zip(buffers, signature.inputs)])
        try:
            gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.float32).reshape(count, stride)
            gl.check_error(f"probe of {name}")
        finally:
            for obj in (vao, result, *buffers, program):
                obj.release()
    out, at = {}, 0
    for p, t in exported:
        w = _WIDTH[t]
        column = data[:, at:at + w] if w == 3 else data[:, at]
        out[p] = column > 0.5 if t == "bool" else column.copy()
        at += w
    return out


def shade_points(gl, programs, key, uniforms, positions, normals, drop_unused=False):
    """Evaluate the GLSL ``shade_point()`` of a 'points' program at arbitrary points.

    Parameters
    ----------
    gl : glphong.contexts.GLContext
    programs : glphong.programs.ProgramCache
        Cache of ``gl``'s programs.
    key : glphong.key.ProgramKey
        With ``output='points'``.
    uniforms : dict of str to array_like
        Exactly the program's active uniforms (strict binding).
    positions, normals : (N, 3) array_like
        World-space points [m] and raw (unnormalised) normals; cast to float32.
    drop_unused : bool
        Drop given uniforms the compiler removed instead of raising (for the naive
        formulation, whose ``safe_normalize`` never fails, so that e.g. a Lambert program
        never reads ``u_eye``); missing uniforms are still an error.

    Returns
    -------
    (N, 3) float32 ndarray
        Radiance [W/(m^2 sr)].
    """
    if key.output != "points":
        raise ValueError(f"key.output must be 'points' (got {key.output!r})")
    positions = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
    normals = np.ascontiguousarray(normals, dtype=np.float32).reshape(-1, 3)
    if positions.shape != normals.shape:
        raise ValueError(f"positions and normals must have the same shape (got {positions.shape} and {normals.shape})")
    count = len(positions)
    mgl = gl.mgl
    with gl:
        program = programs.get(key)
        program.bind(uniforms, drop_unused=drop_unused)
        position_buffer, normal_buffer = mgl.buffer(positions.tobytes()), mgl.buffer(normals.tobytes())
        result = mgl.buffer(reserve=max(count, 1) * 12)
        content = [(b, "3f", name) for b, name in ((position_buffer, "in_position"), (normal_buffer, "in_normal"))
                   if name in program.gl_program]  # the normal is compiled out of unlit programs
        vao = mgl.vertex_array(program.gl_program, content)
        try:
            gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.float32)[:count * 3].reshape(count, 3).copy()
            gl.check_error(f"shade_points of {key.describe()}")
        finally:
            for obj in (vao, result, position_buffer, normal_buffer):
                obj.release()
    return data
