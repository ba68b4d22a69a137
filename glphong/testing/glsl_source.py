"""A user's GLSL source for the shader unit tests (docs/design.md section 14): its ``#include`` lines expanded, its
functions' signatures and its uniforms parsed, and a compiler's log mapped back to the user's files and lines.

``#include`` takes two forms:

- ``#include <glphong/NAME>``: glphong's library chunk ``NAME`` (``common``, ``lobe``, ``fresnel``, ``angle``,
  ``srgb``, ``lights``, ...), with the library chunks before it in glphong's include order (each at most once);
- ``#include "PATH"``: a file relative to the including file's folder.  A source given as a string includes
  relative to ``include_dir``.  No include may leave the top folder (the first file's folder, or
  ``include_dir``) unless ``allow_outside=True``; nesting is limited to 16 levels and the expanded source to 1 MB.

Each file gets a GLSL source-string number through ``#line`` directives, so a compiler's ``0:LINE(COL)`` (Mesa)
or ``0(LINE)`` (NVIDIA) names the user's file and line.
"""
import re
from dataclasses import dataclass, field
from pathlib import Path

from glphong.testing.glsl_types import TYPE_NAMES, glsl_type
from glphong.core.filesafety import LIMITS, SceneFileError, read_bytes
from glphong.core.glsl_files import chunk_source, library_chunks
from glphong.shaders.options import NUMERICS_DEFINES

__all__ = ["GlslSourceError", "Expanded", "expand", "Parameter", "Signature", "functions", "uniforms",
           "strip_comments", "read_source_file", "map_log", "log_locations", "check_signature", "LIBRARY", "LIBRARY_DEFINES", "MAX_SOURCE_BYTES"]

#: glphong's library chunks in include order (``#include <glphong/NAME>``)
LIBRARY = library_chunks()
#: what ``#include <glphong/NAME>`` may name: the library, and the sRGB curve of display outputs
INCLUDABLE = LIBRARY + ("srgb",)
#: the expanded source's limit [bytes]
MAX_SOURCE_BYTES = 1 << 20
_MAX_DEPTH = 16
_INCLUDE = re.compile(r'^\s*#\s*include\s+(?:<([^>\n]*)>|"([^"\n]*)")\s*$')
_VERSION = re.compile(r"^\s*#\s*version\b")
#: defines every library chunk reads, at their defaults (the stable formulation, no tangent, no uv)
LIBRARY_DEFINES = (("NAIVE", "0"), *((define, "0") for define in NUMERICS_DEFINES.values()),
                   ("HAS_TANGENT", "0"), ("HAS_UV", "0"))


class GlslSourceError(ValueError):
    """A GLSL source that cannot be used: an include that cannot be read or is not allowed, a function that does not
    exist or takes a type glphong cannot pass, a compile or link error (its log mapped to the user's lines)."""


@dataclass(frozen=True)
class Expanded:
    """A source with its includes expanded.

    Attributes
    ----------
    text : str
        The expanded source, without a ``#version`` line, with ``#line`` directives.
    files : tuple of str
        The name of each source-string number (0: the top source).
    texts : tuple of str
        The text of each, as read (for messages that quote a line).
    """

    text: str
    files: tuple
    texts: tuple

    def quote(self, number, line, context=1):
        """Lines ``line - context`` to ``line + context`` of file ``number``, numbered (str)."""
        if not 0 <= number < len(self.texts):
            return ""
        lines = self.texts[number].splitlines()
        first, last = max(1, line - context), min(len(lines), line + context)
        return "\n".join(f"  {self.files[number]}:{k}: {lines[k - 1]}" for k in range(first, last + 1))


def _library(name, state, files, texts):
    if name not in INCLUDABLE:
        raise GlslSourceError(f"#include <glphong/{name}>: glphong has no library chunk {name!r} "
                              f"(it has: {', '.join(INCLUDABLE)})")
    out = []
    if not state["library"]:
        out += [f"#define {k} {v}" for k, v in LIBRARY_DEFINES]
    for chunk in INCLUDABLE[:INCLUDABLE.index(name) + 1] if name in LIBRARY else (name,):
        if chunk not in state["library"]:
            state["library"].add(chunk)
            files.append(f"<glphong/{chunk}>")
            texts.append(chunk_source(chunk))
            out += [f"#line 1 {len(files) - 1}", chunk_source(chunk)]
    return "\n".join(out)


def expand(source, origin=None, include_dir=None, allow_outside=False):
    """Expand the includes of a GLSL source.

    Parameters
    ----------
    source : str
        The text of the top source.
    origin : str or pathlib.Path, optional
        The file it was read from: its folder is where its relative includes start and the top folder.
    include_dir : str or pathlib.Path, optional
        For a source given as a string: where its relative includes start (the top folder).
    allow_outside : bool
        Let relative includes reach outside the top folder.

    Returns
    -------
    Expanded
    """
    top = Path(origin).resolve().parent if origin is not None else \
        (Path(include_dir).resolve() if include_dir is not None else None)
    files = [str(origin) if origin is not None else "<source>"]
    texts = [source]
    state = {"library": set(), "size": 0, "stack": []}

    def walk(text, number, folder, depth):
        lines = text.splitlines()
        out = [f"#line 1 {number}"]
        for index, line in enumerate(lines, start=1):
            if _VERSION.match(line):
                out.append("")  # the harness writes its own #version
                continue
            match = _INCLUDE.match(line)
            if match is None:
                out.append(line)
                continue
            where = f"{files[number]}:{index}"
            library, relative = match.groups()
            if library is not None:
                if not library.startswith("glphong/"):
                    raise GlslSourceError(f"{where}: #include <{library}>: the angle-bracket form names glphong's "
                                          f"chunks, <glphong/NAME>; include your own files with quotes")
                try:
                    out.append(_library(library[len("glphong/"):], state, files, texts))
                except GlslSourceError as exc:
                    raise GlslSourceError(f"{where}: {exc}") from None
            else:
                out.append(include(relative, folder, depth, where))
            out.append(f"#line {index + 1} {number}")
        return "\n".join(out)

    def include(relative, folder, depth, where):
        if depth >= _MAX_DEPTH:
            raise GlslSourceError(f"{where}: includes nested more than {_MAX_DEPTH} deep")
        if folder is None:
            raise GlslSourceError(f"{where}: #include \"{relative}\" in a source given as a string: give "
                                  "include_dir= (the folder its includes are relative to) or pass the file's path")
        path = (folder / relative).resolve()
        if not allow_outside and top is not None and top not in path.parents and path != top:
            raise GlslSourceError(f"{where}: #include \"{relative}\" leaves the folder {top} (pass allow_outside=True "
                                  "to allow it)")
        if path in state["stack"]:
            raise GlslSourceError(f"{where}: #include \"{relative}\" includes itself (through "
                                  f"{' -> '.join(p.name for p in state['stack'])})")
        text = read_source_file(path, MAX_SOURCE_BYTES - state["size"], f"{where}: #include \"{relative}\": ")
        state["size"] += len(text.encode("utf-8"))
        if state["size"] > MAX_SOURCE_BYTES:
            raise GlslSourceError(f"{where}: the source with its includes exceeds {MAX_SOURCE_BYTES} bytes")
        files.append(str(path))
        texts.append(text)
        state["stack"].append(path)
        try:
            return walk(text, len(files) - 1, path.parent, depth + 1)
        finally:
            state["stack"].pop()

    if len(source.encode("utf-8")) > MAX_SOURCE_BYTES:
        raise GlslSourceError(f"{files[0]}: larger than {MAX_SOURCE_BYTES} bytes")
    text = walk(source, 0, top, 0)
    return Expanded(text, tuple(files), tuple(texts))


def read_source_file(path, limit=MAX_SOURCE_BYTES, prefix=""):
    """The UTF-8 text of a GLSL file of at most ``limit`` bytes, read as `glphong.filesafety.read_bytes` reads
    (a regular file only, its size checked before a byte is read); a GlslSourceError otherwise."""
    try:
        data = read_bytes(path, LIMITS.replace(file_bytes=max(int(limit), 1)))
        return data.decode("utf-8")
    except SceneFileError as exc:
        raise GlslSourceError(f"{prefix}cannot read {path}: {exc}") from None
    except UnicodeDecodeError as exc:
        raise GlslSourceError(f"{prefix}{path}: not UTF-8 text (byte {exc.start})") from None


def strip_comments(text):
    """``text`` with its comments blanked (newlines kept, so line numbers hold)."""
    def blank(match):
        return re.sub(r"[^\n]", " ", match.group(0))
    return re.sub(r"/\*.*?\*/|//[^\n]*", blank, text, flags=re.S)


@dataclass(frozen=True)
class Parameter:
    """One parameter of a function: ``qualifier`` ``'in'``, ``'out'`` or ``'inout'``, its type and name."""

    qualifier: str
    type: str
    name: str


@dataclass(frozen=True)
class Signature:
    """A GLSL function's signature: ``returns`` (a type name or ``'void'``), ``name`` and its `Parameter` s;
    ``body`` its code between the braces (comments blanked)."""

    returns: str
    name: str
    parameters: tuple
    body: str = field(default="", compare=False, repr=False)

    def __str__(self):
        params = ", ".join(f"{'' if p.qualifier == 'in' else p.qualifier + ' '}{p.type} {p.name}" for p in self.parameters)
        return f"{self.returns} {self.name}({params})"

    @property
    def inputs(self):
        """The parameters a call passes values to (``in`` and ``inout``)."""
        return tuple(p for p in self.parameters if p.qualifier != "out")

    @property
    def outputs(self):
        """``(name, type)`` of what a call gives back: ``'return'`` (unless void), then ``out`` and ``inout``."""
        head = () if self.returns == "void" else (("return", self.returns),)
        return head + tuple((p.name, p.type) for p in self.parameters if p.qualifier != "in")


_IDENT = r"[A-Za-z_]\w*"
_QUALIFIERS = {"const", "highp", "mediump", "lowp", "precise", "in", "out", "inout"}
_DEFINITION = re.compile(rf"(?:^|[;}}\s])(?:(?:highp|mediump|lowp|precise)\s+)*({_IDENT})\s+({_IDENT})\s*\(([^(){{}};]*)\)\s*\{{")


def _code(text):
    """Comments blanked and preprocessor lines dropped (their line kept)."""
    return "\n".join("" if line.lstrip().startswith("#") else line for line in strip_comments(text).splitlines())


def functions(text):
    """Every function definition of ``text`` (expanded source), by name: a list of `Signature` per name (overloads),
    with the parameters' raw types (checked when a function is chosen)."""
    out = {}
    code = _code(text)
    for match in _DEFINITION.finditer(code):
        returns, name, params = match.groups()
        if returns in ("return", "else", "if", "while", "for", "switch", "do"):
            continue
        parameters = []
        body = params.strip()
        if body and body != "void":
            for raw in body.split(","):
                words = raw.split()
                qualifier = "inout" if "inout" in words else "out" if "out" in words else "in"
                words = [w for w in words if w not in _QUALIFIERS]
                if len(words) == 1 and "[" not in words[0]:
                    words.append(f"_{len(parameters)}")  # an unnamed parameter of a prototype
                name_part = " ".join(words[1:])
                parameters.append(Parameter(qualifier, words[0] if words else "?", name_part))
        depth, end = 1, match.end()
        while depth and end < len(code):
            depth += {"{": 1, "}": -1}.get(code[end], 0)
            end += 1
        out.setdefault(name, []).append(Signature(returns, name, tuple(parameters), code[match.end():end - 1]))
    return out


_UNIFORM = re.compile(rf"\buniform\s+(?:(?:highp|mediump|lowp)\s+)*({_IDENT})\s+({_IDENT})\s*(\[[^\]]*\])?\s*;")


def uniforms(text):
    """``{name: type}`` of the uniforms ``text`` declares (array uniforms as ``'type[n]'``)."""
    return {m.group(2): m.group(1) + (m.group(3) or "") for m in _UNIFORM.finditer(_code(text))}


def check_signature(signature):
    """Raise GlslSourceError where a parameter or the result has a type glphong cannot pass."""
    bad = [(p.name, p.type) for p in signature.parameters if glsl_type(p.type) is None or "[" in p.name]
    if signature.returns != "void" and glsl_type(signature.returns) is None:
        bad.append(("the result", signature.returns))
    if bad:
        raise GlslSourceError(f"{signature}: glphong passes {', '.join(TYPE_NAMES)} (scalars, vectors and "
                              f"matrices), not {', '.join(f'{t} ({n})' for n, t in bad)}: wrap the function in one "
                              "that takes and returns those")


_MESA = re.compile(r"^(\d+):(\d+)\((\d+)\):\s*(.*)$")
_NVIDIA = re.compile(r"^(\d+)\((\d+)\)\s*:\s*(.*)$")


def log_locations(log):
    """``(source-string number, line)`` of each location a compiler log names, in order."""
    out = []
    for line in log.splitlines():
        m = _MESA.match(line.strip()) or _NVIDIA.match(line.strip())
        if m:
            out.append((int(m.group(1)), int(m.group(2))))
    return out


def map_log(log, files):
    """A compiler log with each ``STRING:LINE(COL)`` / ``STRING(LINE)`` location written as ``file:line``."""
    out = []
    for line in log.splitlines():
        m = _MESA.match(line.strip())
        if m:
            number, row, rest = int(m.group(1)), m.group(2), f"({m.group(3)}): {m.group(4)}"
        else:
            m = _NVIDIA.match(line.strip())
            if not m:
                out.append(line)
                continue
            number, row, rest = int(m.group(1)), m.group(2), f": {m.group(3)}"
        name = files[number] if number < len(files) else "<generated harness>"
        out.append(f"{name}:{row}{rest}")
    return "\n".join(out)
