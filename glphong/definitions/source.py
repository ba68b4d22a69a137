"""A definition's GLSL: where it comes from, its text, and the names it defines at file scope.

A definition (a material model, a light kind) gives its GLSL as text in the class, as the path of a ``.glsl`` file
beside its module, or as a `GlslFile` of glphong's shader folder.  `resolve_source` reads it with the place it came
from (so a compile error names that file and line); `top_level_names` and `library_names` are what the namespace
checks compare (`glphong.definitions.checks`).
"""
import functools
import inspect
import itertools
import re
import sys
from pathlib import Path

from glphong.core.glsl_files import chunk_source, glsl_root, library_chunks
from glphong.definitions.params import DefinitionError, GlslFile

__all__ = ["strip_comments", "resolve_source", "top_level_names", "library_names"]


def strip_comments(text):
    """The text with its comments blanked (line numbers kept)."""
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def resolve_source(cls):
    """``(text, label, first_line)`` of a definition's GLSL (a material model's, a light kind's): label names
    the file or the class, and ``first_line`` is the line of the text's first line in that file (1 for .glsl
    files).  Errors are the definition's own class (``cls.definition_error``)."""
    error = getattr(cls, "definition_error", DefinitionError)
    glsl = cls.__dict__.get("glsl", cls.glsl)
    if isinstance(glsl, GlslFile):
        try:  # a Traversable: one part at a time; the files ``before`` it first, in order
            names = tuple(glsl.before) + (glsl.path,)
            texts = [glsl_root().joinpath(*name.split("/")).read_text(encoding="utf-8") for name in names]
            if not glsl.before:
                return texts[0], glsl.path, 1
            texts = [text.rstrip("\n") for text in texts]
            starts = itertools.accumulate([1] + [text.count("\n") + 1 for text in texts[:-1]])
            return "\n".join(texts), " + ".join(f"{name} (from line {s})" for name, s in zip(names, starts)), 1
        except OSError as exc:
            raise error(
                f"{cls.__qualname__}: cannot read its GLSL {glsl.path!r} from the shader folder {glsl_root()} "
                f"({exc.strerror}); GLPHONG_GLSL_DIR, when set, must name a full copy of glphong's glsl/ folder, "
                "and be set before glphong is imported") from None
    if isinstance(glsl, Path) or (isinstance(glsl, str) and "\n" not in glsl and glsl.strip().endswith(".glsl")):
        path = Path(glsl)
        if not path.is_absolute():
            module = sys.modules.get(cls.__module__)
            base = Path(getattr(module, "__file__", None) or ".").resolve().parent
            path = base / path
        if not path.is_file():
            raise error(f"{cls.__qualname__}.glsl names the file {str(path)!r}, which does not exist")
        return path.read_text(encoding="utf-8"), str(path), 1
    if not isinstance(glsl, str):
        raise error(f"{cls.__qualname__}.glsl must be GLSL source text or the path of a .glsl file "
                                      f"(got {type(glsl).__name__})")
    label, first = f"{cls.__qualname__}.glsl ({getattr(cls, 'definition_kind', 'material')} {cls.__dict__.get('name', cls.name)!r})", 1
    try:  # where the inline string starts in the Python file, so compile errors name that file and line
        lines, start = inspect.getsourcelines(cls)
        file = inspect.getsourcefile(cls)
        for i, line in enumerate(lines):
            if re.match(r"\s*glsl\s*=\s*[rR]?(\"\"\"|''')", line):
                label, first = f"{file}", start + i
                break
    except (OSError, TypeError):
        pass
    return glsl, label, first


def top_level_names(code):
    """Functions, constants and structs a GLSL text defines at file scope."""
    names, depth, start = set(), 0, 0
    for i, c in enumerate(code + "\n"):
        if c == "{":
            if depth == 0:
                names.update(re.findall(r"\b([A-Za-z_]\w*)\s*\([^()]*\)\s*$", code[start:i]))
                names.update(re.findall(r"\bstruct\s+([A-Za-z_]\w*)\s*$", code[start:i]))
            depth += 1
        elif c == "}":
            depth -= 1
            start = i + 1
        elif c == ";" and depth == 0:
            names.update(re.findall(r"\bconst\s+\w+\s+([A-Za-z_]\w*)\s*=", code[start:i]))
            start = i + 1
    return names


@functools.lru_cache(maxsize=1)
def library_names():
    """What the library chunks define at file scope (read once: the shader folder is fixed at import)."""
    names = {"material_emission", "material_response", "shade_point"}
    for chunk in library_chunks() + ("shade", "srgb"):
        names |= top_level_names(strip_comments(chunk_source(chunk)))
    return frozenset(names)
