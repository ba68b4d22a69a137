"""Any GLSL function as a numpy function: the shader unit tests' runner (docs/design.md section 14).

`glsl_function` compiles a user's GLSL source (a string or a ``.glsl`` file, with ``#include`` s of glphong's
chunks or the user's own files, `glphong.testing.glsl_source`) around a generated harness that calls the function
``name`` once per row and returns its result and its ``out`` and ``inout`` parameters, every value as its 32-bit
patterns (`glphong.testing.glsl_types`).

- ``stage='vertex'`` (default): one row per vertex of a point draw, the results captured by transform feedback,
  up to `VERTEX_CHUNK` rows per draw (larger calls are split; memory grows with the rows: about
  ``4 (inputs + outputs)`` bytes per scalar per row, on the GPU and in numpy).
- ``stage='fragment'``: one row per pixel of a full-screen draw, for what needs the fragment stage: derivatives
  (``dFdx``, ``fwidth``), ``gl_FragCoord``, ``texture()`` with implicit level of detail.  Row ``i`` is the pixel
  ``(i mod W, i div W)`` of a ``W = grid_width`` wide grid (``gl_FragCoord.xy`` = that plus 1/2), so
  neighbouring rows are neighbouring pixels and derivatives are differences between them (GLSL computes them
  over 2x2 quads).  Inputs arrive through integer textures, results through integer colour attachments (at most
  8 slots: a ``mat4`` result takes 4).

Uniforms are set by name (`GlslFunction.set_uniform`, or ``uniforms=`` on a call), samplers by
`GlslFunction.set_texture`.
"""
import struct
import threading
from pathlib import Path

import moderngl
import numpy as np

from glphong.testing.glsl_source import (GlslSourceError, check_signature, expand, functions, log_locations, map_log,
                                         read_source_file, uniforms as parse_uniforms)
from glphong.testing.glsl_types import decode, encode, glsl_type
from glphong.evaluation.pool import pooled

__all__ = ["GlslFunction", "glsl_function", "subnormal_flushing", "VERTEX_CHUNK", "STAGES"]

#: rows per transform-feedback draw; a call with more rows is split into draws of this many
VERTEX_CHUNK = 1 << 20
#: rows per fragment draw at most (the grid's height follows: ``FRAGMENT_CHUNK / grid_width``)
FRAGMENT_CHUNK = 1 << 20
STAGES = ("vertex", "fragment")
_FULL_SCREEN = """
void main() {
    gl_Position = vec4(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID >> 1) * 4 - 1), 0.0, 1.0);
}
"""


def _read_source(source):
    """``(text, origin)`` of a source argument: a path (a ``pathlib.Path``, or a str of one line ending in .glsl,
    .vert, .frag or .comp) is read; any other str is the text."""
    if isinstance(source, Path) or (isinstance(source, str) and "\n" not in source
                                    and source.strip().endswith((".glsl", ".vert", ".frag", ".comp"))):
        path = Path(source)
        return read_source_file(path), path
    if not isinstance(source, str):
        raise TypeError(f"source must be GLSL text or a path to a .glsl file (got {type(source).__name__})")
    return source, None


class GlslFunction:
    """A GLSL function compiled to run on rows of numpy arrays (made by `glsl_function`).

    Call it with one array per ``in`` and ``inout`` parameter (positionally or by name; one row per invocation;
    a value of one row's shape broadcasts).  It returns the function's result as an array where the function has
    no ``out`` or ``inout`` parameter, else a dict: ``'return'`` (unless void) and each ``out``/``inout`` parameter
    by name.  Float results come back bit for bit as the GPU computed them.

    Attributes
    ----------
    signature : glphong.testing.glsl_source.Signature
    stage : {'vertex', 'fragment'}
    uniforms : dict of str to str
        The uniforms the source declares, by name: their GLSL type.
    backend : str
        The context's backend.
    source : str
        The generated program's source (the fragment stage's, for ``stage='fragment'``).
    """

    def __init__(self, source, name, overload=None, stage="vertex", version=330, defines=None, include_dir=None,
                 allow_outside=False, backend="auto", context=None, grid_width=256, origin=None):
        if stage not in STAGES:
            raise ValueError(f"stage must be one of {STAGES} (got {stage!r})")
        if not isinstance(version, int) or version < 330:
            raise ValueError(f"version must be a GLSL core version >= 330 as an int (got {version!r})")
        if not isinstance(grid_width, int) or not 1 <= grid_width <= 4096:
            raise ValueError(f"grid_width must be an int in [1, 4096] (got {grid_width!r})")
        text, path = _read_source(source)
        self._origin = str(path) if path is not None else origin
        self._expanded = expand(text, origin=path, include_dir=include_dir, allow_outside=allow_outside)
        self.signature = self._choose(name, overload)
        check_signature(self.signature)
        self.stage, self.grid_width = stage, grid_width
        self.uniforms = parse_uniforms(self._expanded.text)
        self._defines = dict(defines or {})
        for key, value in self._defines.items():
            if not isinstance(key, str) or not key.isidentifier():
                raise ValueError(f"defines: {key!r} is not a macro name")
            if "\n" in str(value):
                raise ValueError(f"defines: the value of {key} spans lines")
        if context is None:
            self._gl, _, self._lock = pooled(backend)
        else:
            self._gl, self._lock = context, threading.RLock()
        self.backend = getattr(self._gl, "backend", backend)
        self._textures = {}
        self._program = None
        self._compile(version)

    # ------------------------------------------------------------------ building
    def _choose(self, name, overload):
        found = functions(self._expanded.text).get(name)
        if not found:
            known = sorted(functions(self._expanded.text))
            raise GlslSourceError(f"{self._expanded.files[0]}: no function {name!r} is defined (defined: "
                                  f"{', '.join(known) or 'none'})")
        # the same signature twice is one function under #if / #else branches (the compiler keeps one)
        found = list({(s.returns, tuple((p.qualifier, p.type) for p in s.parameters)): s for s in found}.values())
        if overload is not None:
            wanted = tuple(overload)
            found = [s for s in found if tuple(p.type for p in s.parameters) == wanted]
            if not found:
                raise GlslSourceError(f"{name}: no overload takes ({', '.join(wanted)})")
        if len(found) > 1:
            raise GlslSourceError(f"{name} is overloaded: {'; '.join(map(str, found))}. Choose one with "
                                  f"overload=(parameter types...), e.g. overload={tuple(p.type for p in found[0].parameters)!r}")
        return found[0]

    def _harness(self):
        """``(declarations, body, input slots, output slots)`` of the generated caller."""
        sig = self.signature
        inputs, outputs, body, args = [], [], [], []
        for p in sig.parameters:
            t = glsl_type(p.type)
            local = f"glphong_arg_{p.name}"
            if p.qualifier == "out":
                body.append(f"    {p.type} {local};")
            else:
                names = [f"glphong_in_{p.name}_{k}" for k in range(len(t.slots()))]
                inputs += [(n, slot, p.name, k) for k, (n, slot) in enumerate(zip(names, t.slots()))]
                body.append(f"    {p.type} {local} = {t.from_bits(names)};")
            args.append(local)
        call = f"{sig.name}({', '.join(args)})"
        if sig.returns == "void":
            body.append(f"    {call};")
        else:
            body.append(f"    {sig.returns} glphong_result = {call};")
        for name, type_name in sig.outputs:
            t = glsl_type(type_name)
            expression = "glphong_result" if name == "return" else f"glphong_arg_{name}"
            for k, (words, slot) in enumerate(zip(t.to_bits(expression), t.slots())):
                slot_name = f"glphong_out_{name}_{k}"
                outputs.append((slot_name, slot, name, k))
                body.append(f"    {slot_name} = {words};")
        return inputs, outputs, body

    def _compile(self, version):
        header = [f"#version {version} core"] + [f"#define {k} {v}" for k, v in self._defines.items()]
        inputs, outputs, body = self._harness()
        harness = len(self._expanded.files)
        if self.stage == "vertex":
            decl = [f"in {slot[0]} {n};" for n, slot, _, _ in inputs]
            decl += [f"out {slot[0]} {n};" for n, slot, _, _ in outputs]
            main = ["void main() {", "    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);"]
        else:
            decl = [f"uniform usampler2D {n}_texture;" for n, _, _, _ in inputs]
            decl += [f"layout(location = {k}) out {slot[0]} {n};" for k, (n, slot, _, _) in enumerate(outputs)]
            main = ["void main() {", "    ivec2 glphong_texel = ivec2(gl_FragCoord.xy);"]
            main += [f"    {slot[0]} {n} = texelFetch({n}_texture, glphong_texel, 0).{'xyzw'[:slot[1]]};"
                     for n, slot, _, _ in inputs]
        code = "\n".join(header + [self._expanded.text, f"#line 1 {harness}"] + decl + main + body + ["}"]) + "\n"
        self.source = code
        self._inputs, self._outputs = inputs, outputs
        if len(inputs) > 16:
            raise GlslSourceError(f"{self.signature}: its inputs take {len(inputs)} slots (a matrix takes one per "
                                  "column); at most 16 fit")
        if self.stage == "fragment" and len(outputs) > 8:
            raise GlslSourceError(f"{self.signature}: its results take {len(outputs)} colour attachments; the "
                                  "fragment stage has 8 (use stage='vertex')")
        mgl = self._gl.mgl
        try:
            with self._lock, self._gl:
                if self.stage == "vertex":
                    self._program = mgl.program(vertex_shader=code, varyings=[n for n, _, _, _ in outputs])
                else:
                    vertex = f"#version {version} core\n{_FULL_SCREEN}"
                    self._program = mgl.program(vertex_shader=vertex, fragment_shader=code)
        except moderngl.Error as exc:
            raise GlslSourceError(self._compile_message(str(exc))) from None

    def _compile_message(self, log):
        files = self._expanded.files + ("<generated harness>",)
        quoted = [self._expanded.quote(number, line) for number, line in log_locations(log)
                  if number < len(self._expanded.files)]
        harness = self.source[self.source.index("#line 1 " + str(len(self._expanded.files))):].splitlines()[1:]
        numbered = "\n".join(f"  <generated harness>:{k}: {line}" for k, line in enumerate(harness, start=1))
        return (f"{self.signature} does not compile ({self.stage} stage):\n{map_log(log, files)}\n"
                + ("\n".join(q for q in dict.fromkeys(quoted) if q) + "\n" if quoted else "")
                + f"the generated harness that calls it:\n{numbered}")

    # ------------------------------------------------------------------ uniforms and textures
    def set_uniform(self, name, value):
        """Set uniform ``name`` (as the source declares it) to ``value``: a number, a vector (K,), a matrix (R, C)
        as numpy writes it, or an array uniform's values; floats are written as float32 bits."""
        declared = self.uniforms.get(name)
        if declared is None:
            raise KeyError(f"{self.signature.name}: no uniform {name!r} is declared (declared: "
                           f"{', '.join(sorted(self.uniforms)) or 'none'})")
        if "sampler" in declared:
            raise TypeError(f"uniform {name} is a {declared}: give it an image with set_texture")
        if name not in self._program:  # declared but unused: the compiler removed it
            return
        base = declared.split("[")[0]
        t = glsl_type(base)
        dtype = np.float32 if t is None or t.base == "float" else np.int32 if t.base in ("int", "bool") else np.uint32
        array = np.asarray(value, dtype=np.float64 if dtype == np.float32 else np.int64)
        if t is not None and t.is_matrix:
            array = np.swapaxes(array.reshape((-1, t.rows, t.columns)), 1, 2)  # column-major, as GL reads it
        data = np.ascontiguousarray(array.astype(dtype)).tobytes()
        with self._lock, self._gl:
            try:
                self._program[name].write(data)
            except (moderngl.Error, ValueError, struct.error) as exc:
                raise ValueError(f"uniform {name} ({declared}): {np.shape(value)} values do not fit ({exc})") from None

    def set_texture(self, name, image, filter="linear", wrap="clamp", mipmaps=False):
        """Bind an image to sampler uniform ``name``.

        Parameters
        ----------
        image : (H, W) or (H, W, C) array_like
            Rows bottom first, as GL's texture coordinates have them; C in 1..4.  uint8 is normalised to [0, 1];
            anything else is stored as float32.
        filter : {'linear', 'nearest'}
        wrap : {'clamp', 'repeat'}
        mipmaps : bool
            Build mipmaps (trilinear filtering between them).
        """
        declared = self.uniforms.get(name, "")
        if "sampler2D" not in declared:
            raise KeyError(f"{self.signature.name}: no sampler2D uniform {name!r} is declared")
        array = np.asarray(image)
        if array.ndim == 2:
            array = array[..., None]
        if array.ndim != 3 or not 1 <= array.shape[2] <= 4 or min(array.shape[:2]) < 1:
            raise ValueError(f"texture {name}: an image of shape (H, W) or (H, W, 1..4) (got {np.shape(image)})")
        data, dtype = (array, "f1") if array.dtype == np.uint8 else (array.astype(np.float32), "f4")
        with self._lock, self._gl:
            old = self._textures.pop(name, None)
            if old is not None:
                old.release()
            texture = self._gl.mgl.texture((array.shape[1], array.shape[0]), array.shape[2],
                                           np.ascontiguousarray(data).tobytes(), dtype=dtype)
            linear = moderngl.LINEAR_MIPMAP_LINEAR if mipmaps else moderngl.LINEAR
            texture.filter = (linear, moderngl.LINEAR) if filter == "linear" else (moderngl.NEAREST, moderngl.NEAREST)
            texture.repeat_x = texture.repeat_y = wrap == "repeat"
            if mipmaps:
                texture.build_mipmaps()
            self._textures[name] = texture

    # ------------------------------------------------------------------ calling
    def _rows(self, args, kwargs):
        params = self.signature.inputs
        if len(args) > len(params):
            raise TypeError(f"{self.signature} takes {len(params)} inputs (got {len(args)} positional)")
        values = dict(zip((p.name for p in params), args))
        for key, value in kwargs.items():
            if key in values:
                raise TypeError(f"{self.signature}: {key} given twice")
            values[key] = value
        names = [p.name for p in params]
        missing, unknown = [n for n in names if n not in values], sorted(set(values) - set(names))
        if missing or unknown:
            raise TypeError(f"{self.signature} takes inputs {names}" + (f"; missing {missing}" if missing else "")
                            + (f"; unknown {unknown}" if unknown else ""))
        count = None
        for p in params:
            shape = glsl_type(p.type).row_shape()
            array_shape = np.shape(values[p.name])
            if len(array_shape) == len(shape) + 1 and tuple(array_shape[1:]) == shape:
                if count not in (None, array_shape[0]) and array_shape[0] != 1:
                    if count != 1:
                        raise ValueError(f"{self.signature}: inputs have different numbers of rows "
                                         f"({count} and {array_shape[0]} for {p.name})")
                    count = array_shape[0]
                elif count is None or count == 1:
                    count = array_shape[0]
        count = 1 if count is None else count
        return {p.name: encode(glsl_type(p.type), values[p.name], count, f"{self.signature.name}: {p.name}")
                for p in params}, count

    def __call__(self, *args, uniforms=None, **kwargs):
        if self._program is None:
            raise RuntimeError(f"{self.signature.name}: this GlslFunction has been released")
        for name, value in (uniforms or {}).items():
            self.set_uniform(name, value)
        encoded, count = self._rows(args, kwargs)
        words = {(n, k): [] for _, _, n, k in self._outputs}
        # a fragment draw's grid is at most 4096 rows of pixels high (textures of that size exist everywhere)
        chunk = VERTEX_CHUNK if self.stage == "vertex" else min(FRAGMENT_CHUNK, self.grid_width * 4096)
        for start in range(0, count, chunk):
            stop = min(count, start + chunk)
            pieces = self._draw({key: [s[start:stop] for s in slots] for key, slots in encoded.items()}, stop - start)
            for key, piece in pieces.items():
                words[key].append(piece)
        out = {}
        for name, type_name in self.signature.outputs:
            t = glsl_type(type_name)
            slots = [np.concatenate(words[(name, k)]) if words[(name, k)] else
                     np.zeros((0, t.rows), np.uint32) for k in range(len(t.slots()))]
            out[name] = decode(t, slots)
        if list(out) == ["return"]:
            return out["return"]
        return out

    def _draw(self, encoded, count):
        if count == 0:
            return {}
        with self._lock, self._gl:
            if self.stage == "vertex":
                return self._draw_vertex(encoded, count)
            return self._draw_fragment(encoded, count)

    def _bind_textures(self):
        for unit, (name, texture) in enumerate(self._textures.items()):
            if name in self._program:
                texture.use(location=unit)
                self._program[name].value = unit
        return len(self._textures)

    def _draw_vertex(self, encoded, count):
        mgl = self._gl.mgl
        self._bind_textures()
        buffers, content = [], []
        for slot_name, slot, param, k in self._inputs:
            if slot_name not in self._program:  # an input the function does not read
                continue
            buffers.append(mgl.buffer(encoded[param][k].tobytes()))
            content.append((buffers[-1], f"{slot[1]}u", slot_name))
        stride = sum(slot[1] for _, slot, _, _ in self._outputs)
        result = mgl.buffer(reserve=max(count * stride * 4, 4))
        vao = mgl.vertex_array(self._program, content) if content else mgl.vertex_array(self._program, [])
        try:
            self._gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.uint32)[:count * stride].reshape(count, stride)
            self._gl.check_error(f"evaluating {self.signature.name}")
        finally:
            for obj in (vao, result, *buffers):
                obj.release()
        out, at = {}, 0
        for _, slot, name, k in self._outputs:
            out[(name, k)] = data[:, at:at + slot[1]].copy()
            at += slot[1]
        return out

    def _draw_fragment(self, encoded, count):
        mgl = self._gl.mgl
        width = self.grid_width
        height = -(-count // width)
        padded = width * height
        units = self._bind_textures()
        made = []
        try:
            for slot_name, slot, param, k in self._inputs:
                if f"{slot_name}_texture" not in self._program:  # an input the function does not read
                    continue
                words = np.zeros((padded, slot[1]), np.uint32)
                words[:count] = encoded[param][k].reshape(count, slot[1])
                texture = mgl.texture((width, height), slot[1], words.tobytes(), dtype="u4")
                texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
                made.append(texture)
                texture.use(location=units)
                self._program[f"{slot_name}_texture"].value = units
                units += 1
            targets = [mgl.texture((width, height), slot[1], dtype="u4") for _, slot, _, _ in self._outputs]
            made += targets
            fbo = mgl.framebuffer(color_attachments=targets)
            made.append(fbo)
            vao = mgl.vertex_array(self._program, [])
            made.append(vao)
            fbo.use()
            fbo.viewport = (0, 0, width, height)
            mgl.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
            vao.render(moderngl.TRIANGLES, vertices=3)
            out = {}
            for index, (_, slot, name, k) in enumerate(self._outputs):
                raw = fbo.read(components=slot[1], attachment=index, dtype="u4")
                out[(name, k)] = np.frombuffer(raw, np.uint32).reshape(padded, slot[1])[:count].copy()
            self._gl.check_error(f"evaluating {self.signature.name} (fragment stage)")
            self._gl.bind_idle_framebuffer()
        finally:
            for obj in reversed(made):
                obj.release()
        return out

    def release(self):
        """Free the program and textures (the pooled context stays); idempotent."""
        if self._program is None:
            return
        with self._lock, self._gl:
            for texture in self._textures.values():
                texture.release()
            self._program.release()
        self._textures.clear()
        self._program = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()

    def __repr__(self):
        where = f" from {self._origin}" if self._origin else ""
        return f"GlslFunction({self.signature}{where}, stage={self.stage!r})"


def glsl_function(source, name, overload=None, stage="vertex", version=330, defines=None, include_dir=None,
                  allow_outside=False, backend="auto", context=None, grid_width=256):
    """Compile the GLSL function ``name`` of ``source`` to run on numpy arrays, one row per invocation.

    Parameters
    ----------
    source : str or pathlib.Path
        GLSL text, or the path of a ``.glsl`` file (a ``Path``, or a one-line str ending in ``.glsl``, ``.vert``,
        ``.frag`` or ``.comp``).  It may ``#include <glphong/NAME>`` (glphong's library chunks) and
        ``#include "file.glsl"`` (relative to its folder); a ``#version`` line is replaced by the harness's.
    name : str
        The function to call.
    overload : sequence of str, optional
        Its parameter types, where the name is overloaded.
    stage : {'vertex', 'fragment'}
        Where it runs (module docstring): the vertex stage by transform feedback, or the fragment stage for
        derivatives, ``gl_FragCoord`` and implicit-LOD texture sampling.
    version : int
        ``#version <version> core`` (330 or later; 400 for ``dFdxFine``).
    defines : dict, optional
        ``#define NAME VALUE`` lines before the source.
    include_dir : str or pathlib.Path, optional
        Where a string source's relative includes start.
    allow_outside : bool
        Let includes reach outside the top folder.
    backend : {'auto', 'egl', 'osmesa'}
        The pooled context to run on (one per backend per process), unless ``context`` is given.
    context : glphong.gpu.contexts.GLContext, optional
    grid_width : int
        Pixels per row of the fragment stage's grid.

    Returns
    -------
    GlslFunction

    Raises
    ------
    glphong.testing.glsl_source.GlslSourceError
        A function that does not exist, an unsupported parameter type, an include that cannot be read, a source
        that does not compile (the compiler's log mapped to the user's files and lines, and the harness).

    Examples
    --------
    >>> f = glsl_function("vec3 f(vec3 a, float s) { return a * s; }", "f")       # doctest: +SKIP
    >>> f(np.ones((4, 3)), 2.0).shape                                                # doctest: +SKIP
    (4, 3)
    """
    return GlslFunction(source, name, overload=overload, stage=stage, version=version, defines=defines,
                        include_dir=include_dir, allow_outside=allow_outside, backend=backend, context=context,
                        grid_width=grid_width)


def subnormal_flushing(backend="auto", context=None):
    """What the driver does with subnormal float32 values in shader arithmetic (GLSL lets it flush them to zero).

    Returns
    -------
    dict
        ``{'inputs': bool, 'results': bool}``: whether a subnormal operand is read as zero (``x * one`` of
        ``2^-149``), and whether a subnormal result is written as zero (``2^-126 * half``).  Values that only pass
        through (`glsl_function`'s bit-exact transfer) are never flushed.
    """
    with GlslFunction("vec2 glphong_probe_subnormals(float tiny, float least_normal, float one, float half_) "
                      "{ return vec2(tiny * one + 0.0, least_normal * half_); }", "glphong_probe_subnormals",
                      backend=backend, context=context) as fn:  # the factors are inputs: nothing to fold away
        out = fn(np.float32(2.0 ** -149), np.float32(2.0 ** -126), np.float32(1.0), np.float32(0.5))[0]
    return {"inputs": bool(out[0] == 0), "results": bool(out[1] == 0)}
