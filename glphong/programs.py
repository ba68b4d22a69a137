"""GLSL program assembly, compilation, strict uniform binding and caching.

A program's source is generated from its `ProgramKey` alone: a ``#version`` line,
the key's ``#define`` lines, then the key's chunk files, each preceded by a
``#line 1 N`` marker so that a compile error names the chunk file and line.
"""
import ast
import functools
import importlib.resources
import os
import re
import time
from dataclasses import dataclass
from pathlib import Path

import moderngl
import numpy as np

__all__ = ["ProgramCache", "Program", "ShaderCompileError", "UniformError", "assemble", "chunk_source",
           "effective_source"]

GLSL_VERSION = "#version 330 core"
#: line numbers of chunk i start at i * LINE_BLOCK (see `assemble`); a model's generated uniform
#: declarations are numbered from i * LINE_BLOCK + PRELUDE_LINE
LINE_BLOCK = 100000
PRELUDE_LINE = 90000


class ShaderCompileError(RuntimeError):
    """A generated program failed to compile or link; the message names chunk files and lines."""


class UniformError(ValueError):
    """Uniform values do not match what a program declares (missing, unknown or wrong size)."""


def glsl_root():
    """Folder of the chunk files: ``GLPHONG_GLSL_DIR`` when set (a developer's working copy of the
    shaders, used by ``benchmarks/mutation.py``), else the installed ``glphong.glsl`` package, else
    ``glsl/`` beside the package in a source checkout."""
    override = os.environ.get("GLPHONG_GLSL_DIR")
    if override:
        return Path(override)
    try:
        return importlib.resources.files("glphong.glsl")
    except ModuleNotFoundError:  # running from a source checkout: glsl/ beside the package
        return Path(__file__).resolve().parent.parent / "glsl"


@functools.lru_cache(maxsize=None)
def chunk_source(name):
    """Text of the library chunk file ``glsl/<name>.glsl``."""
    return (glsl_root() / f"{name}.glsl").read_text(encoding="utf-8")


@dataclass(frozen=True)
class Chunk:
    """One chunk of a program's source.

    Attributes
    ----------
    label : str
        As the key names it: a library chunk (``'shade'``), a model (``'model:<name>@<source hash>'``)
        or a generated chunk (``'generated:material'``).
    prelude : str
        Generated declarations placed before it (a model's uniforms), outside its line numbering.
    text : str
        The chunk's own source.
    origin : str
        Where the text comes from, for compile errors: a file path or a generated chunk's name.
    first_line : int
        Line number of the text's first line in ``origin`` (a model defined inline in Python
        starts at the line of its ``glsl =``).
    """

    label: str
    prelude: str
    text: str
    origin: str
    first_line: int = 1


def resolve_chunk(label, generated=None):
    """The `Chunk` a key's chunk label stands for.

    Parameters
    ----------
    label : str
    generated : dict of str to str, optional
        The key's generated chunks (`ProgramKey.generated_chunks`).
    """
    if generated and label in generated:
        return Chunk(label, "", generated[label], f"<{label}>")
    if label.startswith("model:"):
        from .materials.model import model_for_key, model_source

        model = model_for_key(*label[len("model:"):].split("@"))
        text, origin, first, _ = model_source(model)
        prelude = f"// uniforms of the model {model.name!r}, declared from its params\n" + model.uniform_declarations()
        return Chunk(label, prelude, text, origin, first)
    return Chunk(label, "", chunk_source(label), f"{label}.glsl")


def assemble(chunks, defines, generated=None, extensions=()):
    """Assemble one stage's source.

    Parameters
    ----------
    chunks : sequence of str
        Chunk labels, in order (see `resolve_chunk`).
    defines : sequence of (str, str)
        ``#define`` name and value pairs.
    generated : dict of str to str, optional
        Text of generated chunks by label.
    extensions : sequence of str
        ``#extension`` directives (``'GL_ARB_texture_query_lod : require'``), placed after ``#version``.

    Returns
    -------
    str
        The source; source-string number ``i + 1`` is chunk ``chunks[i]``, and its lines are
        numbered ``(i + 1) * LINE_BLOCK + line in its origin`` (``#line``), so that a compiler
        location names the chunk even where the compiler reports the wrong source-string number
        (Mesa gives 0 for some semantic errors).
    """
    lines = [GLSL_VERSION]
    lines += [f"#extension {e}" for e in extensions]
    lines += [f"#define {name} {value}" for name, value in defines]
    for number, label in enumerate(chunks, start=1):
        chunk = resolve_chunk(label, generated)
        if chunk.prelude:  # in the chunk's own block, past any line of its text
            lines.append(f"#line {number * LINE_BLOCK + PRELUDE_LINE} {number}")
            lines.append(chunk.prelude)
        lines.append(f"#line {number * LINE_BLOCK + chunk.first_line} {number}")
        lines.append(chunk.text.rstrip("\n"))
    return "\n".join(lines) + "\n"


_DIRECTIVE = re.compile(r"^\s*#\s*(if|ifdef|ifndef|elif|else|endif|define)\b(.*)$")
_IDENTIFIER = re.compile(r"[A-Za-z_]\w*")


#: bound on the magnitude of every value of a preprocessor condition (a larger one is refused)
CONDITION_LIMIT = 2 ** 64
#: longest preprocessor condition evaluated, in characters (after substituting the defines)
CONDITION_MAX_LENGTH = 4096
#: deepest nesting of a preprocessor condition's syntax tree
CONDITION_MAX_DEPTH = 100


def _bounded(value):
    """``value`` where its magnitude is under `CONDITION_LIMIT`; ValueError otherwise."""
    if abs(value) >= CONDITION_LIMIT:
        raise ValueError(f"preprocessor condition: a value of magnitude 2**{abs(value).bit_length() - 1} or more "
                         f"(at most 2**64 - 1 is evaluated)")
    return value


def _truncating_divide(a, b):
    """C's ``a / b`` of integers: the quotient truncated toward zero."""
    if b == 0:
        raise ValueError("preprocessor condition: division by zero")
    quotient = abs(a) // abs(b)
    return quotient if (a < 0) == (b < 0) else -quotient


def _truncating_remainder(a, b):
    """C's ``a % b`` of integers: ``a - b * (a / b)``, with the sign of ``a``."""
    return a - b * _truncating_divide(a, b)


def _shift_count(count):
    """A shift count from 0 to 64 (a larger or negative one is refused)."""
    if not 0 <= count <= 64:
        raise ValueError(f"preprocessor condition: shift by {count} (from 0 to 64 is evaluated)")
    return count


_BINARY_OPERATORS = {
    ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b,
    ast.Div: _truncating_divide, ast.Mod: _truncating_remainder,
    ast.LShift: lambda a, b: a << _shift_count(b), ast.RShift: lambda a, b: a >> _shift_count(b),
    ast.BitAnd: lambda a, b: a & b, ast.BitOr: lambda a, b: a | b, ast.BitXor: lambda a, b: a ^ b,
}
_UNARY_OPERATORS = {ast.UAdd: lambda a: a, ast.USub: lambda a: -a, ast.Invert: lambda a: ~a,
                    ast.Not: lambda a: int(not a)}
_COMPARISONS = {ast.Eq: lambda a, b: a == b, ast.NotEq: lambda a, b: a != b, ast.Lt: lambda a, b: a < b,
                ast.LtE: lambda a, b: a <= b, ast.Gt: lambda a, b: a > b, ast.GtE: lambda a, b: a >= b}


def _condition_value(node, depth=0):
    """The integer value of a node of a translated preprocessor condition (see `_evaluate_condition`)."""
    if depth > CONDITION_MAX_DEPTH:
        raise ValueError(f"preprocessor condition: nested deeper than {CONDITION_MAX_DEPTH} levels")
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return _bounded(node.value)
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY_OPERATORS:
        left, right = _condition_value(node.left, depth + 1), _condition_value(node.right, depth + 1)
        return _bounded(_BINARY_OPERATORS[type(node.op)](left, right))
    if isinstance(node, ast.UnaryOp):
        return _bounded(_UNARY_OPERATORS[type(node.op)](_condition_value(node.operand, depth + 1)))
    if isinstance(node, ast.BoolOp):  # short-circuit, as C's && and || (and Python's and/or)
        value = 0
        for operand in node.values:
            value = _condition_value(operand, depth + 1)
            if bool(value) != isinstance(node.op, ast.And):
                break
        return value
    if isinstance(node, ast.Compare) and all(type(op) in _COMPARISONS for op in node.ops):
        left = _condition_value(node.left, depth + 1)
        for op, comparator in zip(node.ops, node.comparators):
            right = _condition_value(comparator, depth + 1)
            if not _COMPARISONS[type(op)](left, right):
                return 0
            left = right
        return 1
    shown = type(node.op).__name__ if isinstance(node, (ast.BinOp, ast.UnaryOp)) else type(node).__name__
    raise ValueError(f"preprocessor condition: {shown} is not evaluated (integers, + - * / % << >> & | ^ ~, "
                     "comparisons, && || !, defined(NAME) and parentheses are)")


def _evaluate_condition(expression, defines):
    """Value of a preprocessor condition over integer object-like defines (undefined names are 0).

    The condition is translated to Python syntax (``defined(NAME)`` and names to their integers,
    ``&&``, ``||``, ``!`` to ``and``, ``or``, ``not``), parsed with `ast` and evaluated on integers:
    ``+ - * / % << >> & | ^ ~``, comparisons, ``and``/``or``/``not`` and parentheses, with Python's
    precedence and comparison chains; ``/`` and ``%`` truncate toward zero as in C.  Nothing else is
    evaluated (no ``**``, no floats, no calls).

    Parameters
    ----------
    expression : str
        The text after ``#if`` or ``#elif``.
    defines : dict of str to int

    Returns
    -------
    bool

    Raises
    ------
    ValueError
        Where the condition is not such an expression, divides by zero, shifts by more than 64 or
        less than 0, or has a value of magnitude ``2**64`` or more, or is longer than
        `CONDITION_MAX_LENGTH` characters or nested deeper than `CONDITION_MAX_DEPTH`.
    """
    expression = re.sub(r"defined\s*\(?\s*([A-Za-z_]\w*)\s*\)?", lambda m: "1" if m.group(1) in defines else "0", expression)
    python = _IDENTIFIER.sub(lambda m: str(defines.get(m.group(0), 0)), expression)
    python = python.replace("&&", " and ").replace("||", " or ").replace("!=", " __ne__ ")
    python = re.sub(r"!(?!=)", " not ", python).replace(" __ne__ ", "!=").strip()
    if len(python) > CONDITION_MAX_LENGTH:
        raise ValueError(f"preprocessor condition of {len(python)} characters (at most {CONDITION_MAX_LENGTH} are "
                         "evaluated)")
    try:
        tree = ast.parse(python, mode="eval")
    except (SyntaxError, RecursionError, MemoryError) as exc:
        raise ValueError(f"preprocessor condition {expression.strip()[:200]!r} is not an integer expression "
                         f"({type(exc).__name__})") from None
    try:
        return bool(_condition_value(tree.body))
    except RecursionError:
        raise ValueError(f"preprocessor condition: nested deeper than {CONDITION_MAX_DEPTH} levels") from None


def effective_source(source):
    """The source the compiler sees: inactive ``#if`` blocks and ``//`` comments removed.

    Evaluates the integer ``#if``/``#elif``/``#else``/``#endif`` conditions of generated sources
    (``#define`` lines with integer values are honoured; function-like macros are kept as
    text).  For reading and testing what a program contains; GLSL compilation itself uses the
    full source.
    """
    defines, out, stack = {}, [], []  # stack entries: [this block active, some branch taken, parent active]
    for line in source.splitlines():
        m = _DIRECTIVE.match(line)
        active = all(entry[0] for entry in stack)
        if m:
            word, rest = m.group(1), m.group(2).split("//")[0].strip()
            if word in ("if", "ifdef", "ifndef"):
                value = (rest in defines) if word == "ifdef" else (rest not in defines) if word == "ifndef" \
                    else _evaluate_condition(rest, defines)
                stack.append([active and value, value, active])
                continue
            if word == "elif":
                top = stack[-1]
                value = not top[1] and _evaluate_condition(rest, defines)
                top[0], top[1] = top[2] and value, top[1] or value
                continue
            if word == "else":
                top = stack[-1]
                top[0], top[1] = top[2] and not top[1], True
                continue
            if word == "endif":
                stack.pop()
                continue
            if word == "define" and active:
                name, _, value = rest.partition(" ")
                if value.strip().lstrip("-").isdigit():
                    defines[name] = int(value)
        if active:
            code = line.split("//")[0].rstrip()
            if code.strip():
                out.append(code)
    return "\n".join(out) + "\n"


#: ``N:L(C)`` (Mesa), ``N:L`` or ``N(L)`` (NVIDIA): source-string number, line, optional column
_LOCATION = re.compile(r"\b(\d+)(?::(\d+)(?:\((\d+)\))?|\((\d+)\))")


def _name_chunks(log, chunks, generated=None):
    """Rewrite compiler-log locations ``N:L(C)``, ``N:L`` and ``N(L)`` as ``origin:L:C`` / ``origin:L``,
    and show each offending line under the message that names it.

    Source string 0 is the generated ``#version``/``#define`` header; string ``i`` is ``chunks[i - 1]``,
    whose origin is its file (or a model's Python file, lines counted in that file) or generated
    chunk.  Lines at or above `LINE_BLOCK` are decoded as ``(chunk number, line)`` (see `assemble`).
    """
    resolved = [resolve_chunk(label, generated) for label in chunks]
    shown = []

    def repl(m):
        n, line = int(m.group(1)), int(m.group(2) or m.group(4))
        if line >= LINE_BLOCK:  # the line names the chunk, whatever source number was reported
            n, line = line // LINE_BLOCK, line % LINE_BLOCK
        where = f":{line}" + (f":{m.group(3)}" if m.group(3) else "")
        if 1 <= n <= len(resolved):
            chunk = resolved[n - 1]
            origin, index, text = chunk.origin, line - chunk.first_line, chunk.text.splitlines()
            if line >= PRELUDE_LINE:  # the generated uniform declarations of a model
                origin = f"<uniforms of {chunk.label}>"
                index, line, text = line - PRELUDE_LINE, line - PRELUDE_LINE + 1, chunk.prelude.splitlines()
                where = f":{line}" + (f":{m.group(3)}" if m.group(3) else "")
            if 0 <= index < len(text):
                shown.append(f"    {origin}:{line} | {text[index].strip()}")
            return f"{origin}{where}"
        return f"<generated header>{where}" if n == 0 else m.group(0)

    out = []
    for row in log.splitlines():
        shown.clear()
        out.append(_LOCATION.sub(repl, row, count=1))
        out += shown
    return "\n".join(out)


class Program:
    """One compiled program and its strict uniform binding.

    Parameters
    ----------
    mgl : moderngl.Context
    key : glphong.key.ProgramKey
    textures : glphong.textures.TextureStore, optional
        Where the textures of `TableData` uniform values are uploaded (the cache's store).
    """

    def __init__(self, mgl, key, textures=None):
        self.key = key
        self.textures = textures
        defines, generated = key.defines(), key.generated_chunks()
        self.vertex_source = assemble(key.vertex_chunks(), defines, generated)
        self.fragment_source = assemble(key.fragment_chunks(), defines, generated, key.extensions()) \
            if key.fragment_chunks() else None
        try:
            self.gl_program = mgl.program(vertex_shader=self.vertex_source, fragment_shader=self.fragment_source,
                                          varyings=key.varyings())
        except moderngl.Error as exc:
            stage = key.fragment_chunks() if "fragment" in str(exc).lower() else key.vertex_chunks()
            log = _name_chunks(str(exc), stage, generated)
            raise ShaderCompileError(f"program {key.describe()!r} failed to build:\n{log}") from None
        self.active = {name: self.gl_program[name] for name in self.gl_program if isinstance(self.gl_program[name], moderngl.Uniform)}
        # a model's uniforms are declared from its params; one its GLSL does not read for this key (a
        # structural define left it out) is not active, and a value given for it is not an error
        from .materials.model import model_for_key

        self.optional = {model_for_key(t.name, t.source_hash).uniform_name(p.name)
                         for t in getattr(key, "terms", ()) for p in model_for_key(t.name, t.source_hash).uniform_params()}
        #: the bytes last written to each uniform (`write` skips unchanged ones)
        self._written = {}
        #: sampler uniforms in texture-unit order
        self.samplers = tuple(name for name, u in self.active.items() if u.fmt.endswith("i") and "sampler" in
                              _uniform_type(self.vertex_source, self.fragment_source, name))

    def bind(self, values, drop_unused=False):
        """Set every active uniform from ``values``; anything else is an error.

        Parameters
        ----------
        values : dict of str to array_like
            float32 data per uniform name: shape ``()``, ``(k,)``, ``(k, k)`` (row-major
            matrices, transposed here to GL's column-major) or ``(N, 3)`` for arrays; for a
            sampler, a `glphong.materials.TableData` (its texture is uploaded once per context
            and bound to the sampler's unit) or a texture unit the caller bound.
        drop_unused : bool
            Ignore given uniforms that are not active instead of raising: only for the
            naive formulation, whose never-failing ``safe_normalize`` lets the compiler
            remove inputs the stable program reads (e.g. ``u_eye`` of a Lambert program).

        Raises
        ------
        UniformError
            An active uniform is missing, a given name is not an active uniform of the
            program (the key leaves out every uniform it does not use), or the data size
            does not match.
        """
        pack = self.pack(values, drop_unused)
        self.check_complete(pack)
        self.write(pack)

    def pack(self, values, drop_unused=False):
        """``values`` (some of the active uniforms, as in `bind`) checked and packed for `write`.

        Returns
        -------
        tuple of (name, moderngl.Uniform, bytes or TableData)
            The bytes GL receives (matrices transposed), or a table for a sampler.

        Raises
        ------
        UniformError
            A name that is not an active uniform (unless ``drop_unused``, or a model uniform a
            structural define compiled out), or a size that does not match.
        """
        from .materials.surface import TextureImage
        from .materials.table import TableData

        unknown = sorted(n for n in values if n not in self.active and not drop_unused and n not in self.optional)
        if unknown:
            missing = sorted(set(self.active) - set(values))
            raise UniformError(f"program {self.key.describe()!r}: missing uniforms {missing}, unknown uniforms {unknown}")
        out = []
        for name, value in values.items():
            uniform = self.active.get(name)
            if uniform is None:
                continue
            if isinstance(value, (TableData, TextureImage)):
                if name not in self.samplers or self.textures is None:
                    raise UniformError(f"uniform {name} of program {self.key.describe()!r} is not a sampler of a "
                                       "program with a texture store: it cannot take a table")
                out.append((name, uniform, value))
                continue
            # float uniforms take float32; samplers and int uniforms ('1i' formats) take int32
            data = np.asarray(value, dtype=np.int32 if uniform.fmt.endswith("i") else np.float32)
            if data.ndim == 2 and data.shape[0] == data.shape[1] and uniform.dimension == data.size:
                data = data.T
            expected = uniform.array_length * uniform.dimension
            if data.size != expected:
                raise UniformError(f"uniform {name} of program {self.key.describe()!r} takes {expected} floats (got shape {data.shape})")
            out.append((name, uniform, np.ascontiguousarray(data).tobytes()))
        return tuple(out)

    def check_complete(self, *packs):
        """Raise `UniformError` unless ``packs`` together set every active uniform (each once at most)."""
        names = [name for pack in packs for name, _, _ in pack]
        missing = sorted(set(self.active) - set(names))
        if missing or len(names) != len(set(names)):
            repeated = sorted({n for n in names if names.count(n) > 1})
            raise UniformError(f"program {self.key.describe()!r}: missing uniforms {missing}"
                               f"{', given twice ' + str(repeated) if repeated else ''}, unknown uniforms []")

    def write(self, pack):
        """Write a `pack` to GL, skipping uniforms whose bytes this program already holds (GL keeps a
        program's uniform values); a table's texture is bound to its sampler's unit every time (other
        programs use the units too)."""
        last = self._written
        for name, uniform, data in pack:
            if not isinstance(data, bytes):  # a table
                unit = self.samplers.index(name)
                self.textures.bind(data, unit)
                data = np.int32(unit).tobytes()
            if last.get(name) != data:
                uniform.write(data)
                last[name] = data

    def release(self):
        """Release the GL program."""
        self.gl_program.release()


def _uniform_type(vertex_source, fragment_source, name):
    """The declared GLSL type of uniform ``name`` in a program's sources ('' where not found)."""
    for source in (vertex_source, fragment_source or ""):
        m = re.search(rf"^\s*uniform\s+(\w+)\s+{re.escape(name)}\s*[;\[]", source, re.M)
        if m:
            return m.group(1)
    return ""


class ProgramCache:
    """Programs of one GL context, compiled once per `ProgramKey`, and the textures they sample.

    Attributes
    ----------
    textures : glphong.textures.TextureStore
        The tables the programs' samplers have read, uploaded once each.
    hits, misses : int
        Cache statistics since creation.
    compile_seconds : float
        Total wall time spent compiling and linking.
    """

    def __init__(self, mgl):
        from .textures import TextureStore

        self._mgl = mgl
        self._programs = {}
        self.textures = TextureStore(mgl)
        self.hits = 0
        self.misses = 0
        self.compile_seconds = 0.0

    def get(self, key):
        """The program for ``key``, compiled on first use."""
        program = self._programs.get(key)
        if program is not None:
            self.hits += 1
            return program
        self.misses += 1
        start = time.perf_counter()
        program = self._programs[key] = Program(self._mgl, key, self.textures)
        self.compile_seconds += time.perf_counter() - start
        return program

    def keys(self):
        """Keys of the compiled programs."""
        return tuple(self._programs)

    def __len__(self):
        return len(self._programs)

    def release(self):
        """Release every program and texture."""
        for program in self._programs.values():
            program.release()
        self._programs.clear()
        self.textures.release()
