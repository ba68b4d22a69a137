"""Evaluate single GLSL functions on the GPU, one input row per vertex, via transform feedback.

This is how each GLSL chunk function is tested against its numpy twin of the same
name (docs/design.md section 7, layer 1): the function is called from a generated vertex
shader on float32 inputs and its return value and ``out`` parameters are captured.

Example
-------
>>> with glphong.create_context("egl") as gl:                               # doctest: +SKIP
...     out = probe.evaluate(gl, "lobe_from_delta", delta=[0.0, 1e-6], q=[1e6, 1e6])
...     out["return"]
"""
import importlib
import re
from dataclasses import dataclass

import moderngl
import numpy as np

from glphong.materials.params import LIBRARY_CHUNKS
from glphong.core.glsl_files import GLSL_VERSION, chunk_source
from glphong.shaders.assembly import resolve_chunk
from glphong.materials import registered_models
from glphong.materials.registry import _strip_comments

__all__ = ["Signature", "signatures", "twin_of", "evaluate", "shade_points"]

_WIDTH = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4, "bool": 1}
#: library chunks whose functions can be probed, in include order
LIBRARY = ("common", "lights") + LIBRARY_CHUNKS + ("area", "normal_map")
#: defines every probe source carries (the key's switches at their defaults)
_PROBE_DEFINES = (("NAIVE", "0"), ("HAS_TANGENT", "0"), ("HAS_UV", "0"))


@dataclass(frozen=True)
class Signature:
    """A GLSL function's parameters and the chunks that define it.

    Attributes
    ----------
    chunks : tuple of str
        Chunk labels to include, in order.
    inputs : tuple of (str, str)
        ``(name, glsl type)`` of the ``in`` parameters, in order.
    outputs : tuple of (str, str)
        ``(name, glsl type)`` of the ``out`` parameters, in order.
    returns : str
        GLSL return type.
    twin_module : str
        Module of its numpy twin of the same name.
    """

    chunks: tuple
    inputs: tuple
    outputs: tuple
    returns: str
    twin_module: str = "glphong.reference"


_FUNCTION = re.compile(r"^(float|vec2|vec3|vec4|bool|void)\s+([A-Za-z_]\w*)\s*\(([^)]*)\)\s*\{", re.M)


def _parse(text, chunks, twin_module, uniforms=None):
    """Pure functions of a chunk's text (those of float/vec/bool parameters that read no uniform)."""

    code = _strip_comments(text)
    out = {}
    for m in _FUNCTION.finditer(code):
        depth, i = 1, m.end()
        while depth and i < len(code):
            depth += {"{": 1, "}": -1}.get(code[i], 0)
            i += 1
        body = code[m.end():i]
        inputs, outputs, ok = [], [], True
        for param in filter(None, (p.strip() for p in m.group(3).split(","))):
            words = param.split()
            qualifier = words[0] if words[0] in ("in", "out", "inout") else "in"
            words = words[1:] if words[0] in ("in", "out", "inout") else words
            if len(words) != 2 or words[0] not in _WIDTH or qualifier == "inout":
                ok = False
                break
            (outputs if qualifier == "out" else inputs).append((words[1], words[0]))
        reads = set(re.findall(r"\bu_\w+", body))  # a local named u_x is not a uniform where the names are known
        if ok and not (reads & uniforms if uniforms is not None else reads):
            out[m.group(2)] = Signature(tuple(chunks), tuple(inputs), tuple(outputs), m.group(1), twin_module)
    return out


def signatures():
    """Every probeable GLSL function of the library chunks and of every registered model, by name.

    Returns
    -------
    dict of str to Signature
        A function's numpy twin has the same name, in ``Signature.twin_module`` (`twin_of`).
    """

    out = {}
    for chunk in LIBRARY:
        out.update(_parse(chunk_source(chunk), LIBRARY, "glphong.reference"))
    for model in registered_models():
        chunks = LIBRARY + (f"model:{model.name}@{model.source_hash()}",)
        names = {model.uniform_name(p.name) for p in model.uniform_params() + model.tables}
        out.update(_parse(model.source(), chunks, model.__module__, names))
    return out


def twin_of(name):
    """The numpy twin of GLSL function ``name`` (same name, in the module its signature names)."""
    signature = signatures()[name]
    return getattr(importlib.import_module(signature.twin_module), name)


def _exported(signature):
    """``(name, type)`` of what a probe captures: the return value (unless void), then the outs."""
    head = () if signature.returns == "void" else (("return", signature.returns),)
    return head + signature.outputs


def probe_source(name, signature):
    """The vertex shader that calls ``name`` once per vertex and exports its results."""
    lines = [GLSL_VERSION] + [f"#define {k} {v}" for k, v in _PROBE_DEFINES]
    for label in signature.chunks:
        chunk = resolve_chunk(label)
        lines += [chunk.prelude, chunk.text] if chunk.prelude else [chunk.text]
    lines += [f"in {t} in_{p};" for p, t in signature.inputs]
    exported = _exported(signature)
    lines += [f"out {'float' if t == 'bool' else t} out_{p};" for p, t in exported]
    lines.append("void main() {")
    lines += [f"    {t} local_{p};" for p, t in signature.outputs]
    args = [f"in_{p}" for p, _ in signature.inputs] + [f"local_{p}" for p, _ in signature.outputs]
    if signature.returns == "void":
        lines.append(f"    {name}({', '.join(args)});")
    else:
        lines.append(f"    {signature.returns} result = {name}({', '.join(args)});")
        lines.append("    out_return = " + ("result ? 1.0 : 0.0;" if signature.returns == "bool" else "result;"))
    lines += [f"    out_{p} = local_{p};" for p, _ in signature.outputs]
    lines.append("}")
    return "\n".join(lines) + "\n"


def evaluate(gl, name, **inputs):
    """Call GLSL function ``name`` on rows of float32 inputs.

    Parameters
    ----------
    gl : glphong.gpu.contexts.GLContext
    name : str
        A key of `signatures()`: a library or model chunk function.
    **inputs : array_like
        One array per ``in`` parameter: shape ``(N,)`` for float, ``(N, k)`` for veck;
        scalars broadcast.  Cast to float32.

    Returns
    -------
    dict of str to ndarray
        ``'return'`` and each ``out`` parameter, float32 (bool as ``bool``), shape ``(N,)`` or ``(N, k)``.
    """
    known = signatures()
    if name not in known:
        raise KeyError(f"no probeable GLSL function {name!r} (known: {', '.join(sorted(known))})")
    signature = known[name]
    names = [p for p, _ in signature.inputs]
    if sorted(inputs) != sorted(names):
        raise TypeError(f"{name} takes inputs {names} (got {sorted(inputs)})")
    columns = [np.asarray(inputs[p], dtype=np.float32) for p in names]
    count = max(c.shape[0] if c.ndim and (c.ndim == 2 or _WIDTH[t] == 1) else 1
                for c, (_, t) in zip(columns, signature.inputs))
    columns = [np.ascontiguousarray(np.broadcast_to(c, (count, _WIDTH[t]) if _WIDTH[t] > 1 else (count,)))
               for c, (_, t) in zip(columns, signature.inputs)]
    exported = _exported(signature)
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
        column = data[:, at:at + w] if w > 1 else data[:, at]
        out[p] = column > 0.5 if t == "bool" else column.copy()
        at += w
    return out


def shade_points(gl, programs, key, uniforms, positions, normals, drop_unused=False, tangents=None, uvs=None):
    """Evaluate the GLSL ``shade_point()`` of a 'points' program at arbitrary points.

    Parameters
    ----------
    gl : glphong.gpu.contexts.GLContext
    programs : glphong.gpu.programs.ProgramCache
        Cache of ``gl``'s programs.
    key : glphong.shaders.key.ProgramKey
        With ``output='points'``.
    uniforms : dict of str to array_like
        Exactly the program's active uniforms (strict binding).
    positions, normals : (N, 3) array_like
        World-space points [m] and raw (unnormalised) normals; cast to float32.
    drop_unused : bool
        Drop given uniforms the compiler removed instead of raising (for the naive
        formulation, whose ``safe_normalize`` never fails, so that e.g. a Lambert program
        never reads ``u_eye``); missing uniforms are still an error.
    tangents : (N, 4) array_like, optional
        Raw tangents with handedness in w, where the key reads them (default (1, 0, 0, 1)).
    uvs : (N, 2) array_like, optional
        Texture coordinates, where the key reads them (default 0).

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
    columns = {"in_position": (positions, "3f"), "in_normal": (normals, "3f")}
    if key.has_tangent:
        tangents = np.broadcast_to((1.0, 0.0, 0.0, 1.0) if tangents is None else tangents, (count, 4))
        columns["in_tangent"] = (np.ascontiguousarray(tangents, dtype=np.float32), "4f")
    if key.has_uv:
        uvs = np.broadcast_to(0.0 if uvs is None else uvs, (count, 2))
        columns["in_uv"] = (np.ascontiguousarray(uvs, dtype=np.float32), "2f")
    mgl = gl.mgl
    with gl:
        program = programs.get(key)
        program.bind(uniforms, drop_unused=drop_unused)
        buffers = {name: mgl.buffer(data.tobytes()) for name, (data, _) in columns.items()}
        result = mgl.buffer(reserve=max(count, 1) * 12)
        content = [(buffers[name], fmt, name) for name, (_, fmt) in columns.items()
                   if name in program.gl_program]  # the normal is compiled out of unlit programs
        vao = mgl.vertex_array(program.gl_program, content)
        try:
            gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.float32)[:count * 3].reshape(count, 3).copy()
            gl.check_error(f"shade_points of {key.describe()}")
        finally:
            for obj in (vao, result, *buffers.values()):
                obj.release()
    return data
