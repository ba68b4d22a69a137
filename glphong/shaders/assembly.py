"""A program's source as text: chunks resolved and assembled with ``#line`` markers, the preprocessor
that shows what the compiler sees, and compiler logs mapped back to chunk files.

A stage's source is a ``#version`` line, the key's ``#define`` lines, then the key's chunks, each
preceded by ``#line`` so that a compile error names the chunk file and line (`assemble`,
`name_chunks`).  `effective_source` evaluates the integer ``#if`` conditions of a source over a checked
syntax tree of bounded integers (never ``eval``), for reading and testing what a program contains.
"""
import ast
import re
from dataclasses import dataclass

from glphong.core.glsl_files import GLSL_VERSION, chunk_source
from glphong.definitions.light import light_for_key, light_source
from glphong.definitions.registry import model_for_key, model_source

__all__ = ["Chunk", "resolve_chunk", "assemble", "effective_source", "name_chunks", "LINE_BLOCK", "PRELUDE_LINE"]

#: line numbers of chunk i start at i * LINE_BLOCK (see `assemble`); a model's generated uniform
#: declarations are numbered from i * LINE_BLOCK + PRELUDE_LINE
LINE_BLOCK = 100000
PRELUDE_LINE = 90000


@dataclass(frozen=True)
class Chunk:
    """One chunk of a program's source.

    Attributes
    ----------
    label : str
        As the key names it: a library chunk (``'shade'``), a model (``'model:<name>@<source hash>'``), a
        light kind (``'light:<name>@<source hash>'``) or a generated chunk (``'generated:material'``).
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
        model = model_for_key(*label[len("model:"):].split("@"))
        text, origin, first, _ = model_source(model)
        prelude = f"// uniforms of the model {model.name!r}, declared from its params\n" + model.uniform_declarations()
        return Chunk(label, prelude, text, origin, first)
    if label.startswith("light:"):
        kind = light_for_key(*label[len("light:"):].split("@"))
        text, origin, first, _ = light_source(kind)
        prelude = f"// uniform arrays of the light kind {kind.name!r}, declared from its uniforms\n" + kind.uniform_declarations()
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


def name_chunks(log, chunks, generated=None):
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
