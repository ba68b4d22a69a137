"""The registry of material models and their GLSL sources.

A `MaterialModel` subclass registers itself by name when its class is created (`register`); program
assembly finds a model's source through here (`model_for_key`, `model_source`), never the reverse.
A model's source hash covers its uniform declarations, the library chunks it uses and its text.
"""
import functools
import hashlib
import inspect
import re
import sys
from pathlib import Path

from glphong.core.glsl_files import chunk_source, glsl_root, library_chunks
from glphong.materials.params import GlslFile
from glphong.materials.params import MaterialDefinitionError as _MaterialDefinitionError

__all__ = ["registered_models", "model_named", "model_source", "model_for_key", "register"]

_REGISTRY = {}
_SOURCES = {}


def register(cls):
    """Register model class ``cls`` under its name (a re-run of the same definition replaces it)."""
    existing = _REGISTRY.get(cls.name)
    if existing is not None:
        _SOURCES.pop(existing, None)
    _REGISTRY[cls.name] = cls


def registered_models():
    """Every defined `MaterialModel` subclass, built-in and user, sorted by name (tuple)."""
    return tuple(_REGISTRY[name] for name in sorted(_REGISTRY))


def model_named(name):
    """The `MaterialModel` subclass registered as ``name``.

    Raises
    ------
    KeyError
        No model has that name.
    """
    try:
        return _REGISTRY[name]
    except KeyError:
        raise KeyError(f"no material model is named {name!r} (defined: {', '.join(sorted(_REGISTRY))})") from None


def _is_builtin(cls):
    return cls.__module__.startswith("glphong.")


def _strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def _resolve_source(cls):
    """``(text, label, first_line)`` of a definition's GLSL (a material model's, a light kind's): label names
    the file or the class, and ``first_line`` is the line of the text's first line in that file (1 for .glsl
    files).  Errors are the definition's own class (``cls.definition_error``, `MaterialDefinitionError` by
    default)."""
    MaterialDefinitionError = getattr(cls, "definition_error", _MaterialDefinitionError)  # noqa: N806
    glsl = cls.__dict__.get("glsl", cls.glsl)
    if isinstance(glsl, GlslFile):
        path = glsl_root().joinpath(*glsl.path.split("/"))  # a Traversable: one part at a time
        try:
            return path.read_text(encoding="utf-8"), glsl.path, 1
        except OSError as exc:
            raise MaterialDefinitionError(
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
            raise MaterialDefinitionError(f"{cls.__qualname__}.glsl names the file {str(path)!r}, which does not exist")
        return path.read_text(encoding="utf-8"), str(path), 1
    if not isinstance(glsl, str):
        raise MaterialDefinitionError(f"{cls.__qualname__}.glsl must be GLSL source text or the path of a .glsl file "
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


_BY_HASH = {}


def hashed_source(cls, sources, by_hash):
    """``(text, label, first_line, source_hash)`` of a definition's GLSL, cached in ``sources`` (by class) and
    ``by_hash`` (class by ``(name, hash)``): the registry's caches of materials or of light kinds.

    The hash covers everything the definition's chunk is made of: its uniform declarations (from
    `params`), the library chunks it uses and its text, so an edited definition is another program.
    """
    cached = sources.get(cls)
    if cached is None:
        text, label, first = _resolve_source(cls)
        whole = "\n".join([cls.uniform_declarations(), " ".join(cls.uses), text])
        digest = hashlib.sha256(whole.encode("utf-8")).hexdigest()[:12]
        cached = sources[cls] = (text, label, first, digest)
        by_hash[(cls.name, digest)] = cls
    return cached


def model_source(cls):
    """``(text, label, first_line, source_hash)`` of a model's GLSL (cached per class; `hashed_source`)."""
    return hashed_source(cls, _SOURCES, _BY_HASH)


def model_for_key(name, source_hash):
    """The model class a program key's term was made from (by name and source hash): a class that was
    redefined since (a re-run notebook cell) still builds its own programs."""
    cls = _BY_HASH.get((name, source_hash))
    if cls is None:
        cls = model_named(name)
        if cls.source_hash() != source_hash:
            raise KeyError(f"no definition of the material model {name!r} has source hash {source_hash}")
    return cls


def _top_level_names(code):
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


def _generated_names(cls):
    """The uniform and switch names glphong generates for a model."""
    names = {cls.uniform_name(p.name) for p in cls.uniform_params() + cls.tables}
    names |= {cls.uniform_name(f"{p.name}_{suffix}") for p in cls.params if p.textureable for suffix in ("scale", "texture")}
    names |= {f"u_use_{cls.name}", f"u_use_{cls.name}_ambient"}
    return names | ({f"{cls.name}_fresnel"} if cls.fresnel_slot is not None else set())


@functools.lru_cache(maxsize=1)
def _library_names():
    """What the library chunks define at file scope (read once: the shader folder is fixed at import)."""
    names = {"material_emission", "material_response", "shade_point"}
    for chunk in library_chunks() + ("shade", "srgb"):
        names |= _top_level_names(_strip_comments(chunk_source(chunk)))
    return frozenset(names)


_MODEL_NAMES = {}


def _model_names(cls):
    """What a registered model's GLSL defines at file scope, once per definition (name and source hash)."""
    key = (cls.name, cls.source_hash())
    names = _MODEL_NAMES.get(key)
    if names is None:
        names = _MODEL_NAMES[key] = frozenset(_top_level_names(_strip_comments(cls.source())))
    return names


