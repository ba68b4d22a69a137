"""The definition-time checks every sort of definition passes (a material model's, a light kind's).

Each raises the definition's own error (``cls.definition_error``) saying what is wrong and what to write instead:
its name, its parameter tuples, the library chunks it uses, the uniforms its GLSL reads, the names its GLSL defines
at file scope (which share one program with the library and every other definition) and its numpy twin's signature.
The sort-specific checks (`glphong.definitions.material_checks`, `glphong.definitions.light_checks`) call these.
"""
import inspect
import re

from glphong.definitions.params import _GLSL_KEYWORDS, _IDENT, RESERVED_NAMES, Param
from glphong.definitions.registry import is_builtin
from glphong.definitions.source import library_names, top_level_names

__all__ = ["check_name", "check_params", "check_not_shadowing", "check_uses", "check_uniform_reads",
           "check_library_clash", "twin_arguments"]


def check_name(cls, example):
    """``name`` is a lowercase GLSL identifier (``example`` in the message), not reserved by glphong's shading code
    or GLSL (the built-in light kinds own some reserved names: 'point', 'directional')."""
    name = cls.name
    if not isinstance(name, str) or not _IDENT.match(name) or "__" in name or name.endswith("_"):
        raise cls.definition_error(f"{cls.__qualname__}.name must be a lowercase GLSL identifier such as "
                                   f"{example!r} (got {name!r})")
    reserved = name in RESERVED_NAMES or name in _GLSL_KEYWORDS or name.startswith("gl_")
    if reserved and not (cls.definition_kind == "light" and is_builtin(cls)):
        raise cls.definition_error(f"{cls.__qualname__}.name {name!r} is reserved by glphong's shading code "
                                   "or GLSL; choose another")


def check_params(cls, attr):
    """``cls.<attr>`` is a tuple of `Param` with distinct names; returns the names."""
    value = getattr(cls, attr)
    if not isinstance(value, tuple) or not all(isinstance(p, Param) for p in value):
        raise cls.definition_error(f"{cls.__qualname__}.{attr} must be a tuple of glphong.materials.Param")
    names = [p.name for p in value]
    if len(set(names)) != len(names):
        raise cls.definition_error(f"{cls.__qualname__}.{attr} repeats a name ({names})")
    return names


def check_not_shadowing(cls, names, base):
    """No parameter named like an attribute of the sort's base class ``base``."""
    shadowing = sorted(set(names) & set(dir(base)))
    if shadowing:
        raise cls.definition_error(f"{cls.__qualname__}.params: {', '.join(shadowing)} would shadow a "
                                   f"{base.__name__} attribute; choose other parameter names")


def check_uses(cls, allowed):
    """``uses`` is a tuple of the library chunks ``allowed``."""
    if not isinstance(cls.uses, tuple) or not set(cls.uses) <= set(allowed):
        raise cls.definition_error(f"{cls.__qualname__}.uses must be a tuple of library chunks "
                                   f"{', '.join(map(repr, allowed))} (got {cls.uses!r})")


def check_uniform_reads(cls, code, declared, may_be_unread=(), what="uniform", listing="uniforms",
                        every="every uniform is an array the light function must use"):
    """The GLSL ``code`` (comments stripped) reads ``u_<name>_<x>`` for exactly the ``declared`` names (less those
    generated code reads, ``may_be_unread``), and declares none of them itself; ``what``, ``listing`` and ``every``
    word the messages for the sort."""
    name = cls.name
    read = set(re.findall(rf"\bu_{name}_([A-Za-z_]\w*)", code))
    if read - set(declared):
        raise cls.definition_error(
            f"{cls.__qualname__}.glsl reads {', '.join(f'u_{name}_{x}' for x in sorted(read - set(declared)))}, "
            f"which no {what} declares ({listing}: {', '.join(sorted(declared)) or 'none'})")
    unread = set(declared) - read - set(may_be_unread)
    if unread:
        raise cls.definition_error(
            f"{cls.__qualname__}.glsl never reads {', '.join(f'u_{name}_{x}' for x in sorted(unread))}: "
            f"{every} (or remove it)")
    if re.search(rf"\buniform\s+\w+\s+u_{name}_", code):
        raise cls.definition_error(f"{cls.__qualname__}.glsl declares its own u_{name}_* uniforms: glphong "
                                   f"declares them from its {listing}; remove the declarations")


def check_library_clash(cls, code):
    """What the GLSL defines at file scope must not be what a library chunk defines; returns those names."""
    own = top_level_names(code)
    clash = own & library_names()
    if clash:
        raise cls.definition_error(f"{cls.__qualname__}.glsl defines {', '.join(sorted(clash))}, which glphong's "
                                   f"library chunks define; prefix your functions with {cls.name}_")
    return own


def twin_arguments(method):
    """The positional parameters of a twin method after ``self`` (list of `inspect.Parameter`), or None where the
    signature cannot be read or takes ``*args``."""
    try:
        params = list(inspect.signature(method).parameters.values())[1:]
    except (TypeError, ValueError):
        return None
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return None
    return [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
