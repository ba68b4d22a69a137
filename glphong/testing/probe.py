"""Evaluate single GLSL functions on the GPU, one input row per vertex, via transform feedback.

This is how each GLSL chunk function is tested against its numpy twin of the same
name (docs/design.md section 7, layer 1): the function is called from a generated vertex
shader on float32 inputs and its return value and ``out`` parameters are captured, through the public
`glphong.testing.glsl_function`.  (A 'points' program's ``shade_point()`` at given points is the render check's
`glphong.checks.points.shade_points`.)

Example
-------
>>> with glphong.create_context("egl") as gl:                               # doctest: +SKIP
...     out = probe.evaluate(gl, "lobe_from_delta", delta=[0.0, 1e-6], q=[1e6, 1e6])
...     out["return"]
"""
import importlib
import re
from dataclasses import dataclass

from glphong.checks.points import shade_points  # noqa: F401 - the old path glphong.checks.probe's, one release
from glphong.core.glsl_files import chunk_source
from glphong.materials import registered_models
from glphong.shaders.assembly import resolve_chunk
from glphong.testing.glsl_runner import glsl_function
from glphong.testing.glsl_source import LIBRARY, LIBRARY_DEFINES, functions

__all__ = ["Signature", "signatures", "twin_of", "library_source", "evaluate"]

_WIDTH = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4, "bool": 1}


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


def _parse(text, chunks, twin_module, uniforms=None):
    """Pure functions of a chunk's text (those of float/vec/bool parameters that read no uniform), as
    `glphong.testing.glsl_source.functions` finds them."""
    out = {}
    for name, found in functions(text).items():
        for sig in found:
            if sig.returns not in (*_WIDTH, "void") or any(p.type not in _WIDTH or p.qualifier == "inout"
                                                           for p in sig.parameters):
                continue
            reads = set(re.findall(r"\bu_\w+", sig.body))  # a local named u_x is not a uniform where the names are known
            if not (reads & uniforms if uniforms is not None else reads):
                inputs = tuple((p.name, p.type) for p in sig.parameters if p.qualifier == "in")
                outputs = tuple((p.name, p.type) for p in sig.parameters if p.qualifier == "out")
                out[name] = Signature(tuple(chunks), inputs, outputs, sig.returns, twin_module)
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


def library_source(signature):
    """The GLSL text of a probeable function's chunks (with the key's switches at their defaults), for
    `glphong.testing.glsl_function`."""
    lines = [f"#define {k} {v}" for k, v in LIBRARY_DEFINES]
    for label in signature.chunks:
        chunk = resolve_chunk(label)
        lines += [chunk.prelude, chunk.text] if chunk.prelude else [chunk.text]
    return "\n".join(lines) + "\n"


def evaluate(gl, name, **inputs):
    """Call GLSL function ``name`` of glphong's chunks on rows of float32 inputs, through the public
    `glphong.testing.glsl_function`.

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
    with glsl_function(library_source(signature), name, context=gl) as fn:
        out = fn(**inputs)
    return out if isinstance(out, dict) else {"return": out}
