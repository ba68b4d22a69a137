"""The checks a `LightModel` subclass passes when its class is created (docs/design.md section 11).

Each raises `LightDefinitionError` saying what is wrong and what to write instead: the shared checks of every
definition (`glphong.definitions.checks`: the name, the parameter tuples, ``uses``, the uniforms the GLSL reads, the
names it defines) and the light's own: ``uniforms`` with their ``uniform_value``, ``shadow_map`` and the parameter it
needs, ``numerics_bounds``, the contract functions (``<name>_incident`` and its twin) and an extended kind's
``exact``.
"""
import re

from glphong.core.glsl_files import library_chunks
from glphong.definitions.checks import (check_library_clash, check_name, check_not_shadowing, check_params,
                                        check_uniform_reads, check_uses, twin_arguments)
from glphong.definitions.registry import registered_models
from glphong.definitions.source import strip_comments

__all__ = ["check_light_definition"]


def check_light_definition(cls, base):
    """The definition-time checks of a `LightModel` subclass ``cls`` (``base``: `LightModel` itself, whose attributes a
    parameter must not shadow); raises ``cls.definition_error`` (`LightDefinitionError`)."""
    err = cls.definition_error
    name = cls.name
    check_name(cls, "luminaire")
    clash = [m for m in registered_models() if m.name == name]
    if clash:
        raise err(f"{cls.__qualname__}.name {name!r} is the name of the material model "
                  f"{clash[0].__module__}.{clash[0].__qualname__} (their uniforms u_{name}_* would clash); choose another")
    for attr in ("params", "uniforms"):
        value = getattr(cls, attr)
        if attr == "uniforms" and value is None:
            continue
        check_params(cls, attr)
        if any(p.textureable for p in value):
            raise err(f"{cls.__qualname__}.{attr}: a light's parameters are constants (textureable is for materials)")
    check_not_shadowing(cls, [p.name for p in cls.params], base)
    check_uses(cls, library_chunks("light"))
    if cls.uniforms is not None and "uniform_value" not in {k for c in cls.__mro__[:-1] if c is not base
                                                            for k in c.__dict__}:
        raise err(f"{cls.__qualname__} declares uniforms different from its params, so it must define "
                  "uniform_value(self, name) giving each uniform's value")
    if cls.shadow_map not in (None, "cube", "ortho"):
        raise err(f"{cls.__qualname__}.shadow_map must be None, 'cube' (a light at its `position`) or 'ortho' (a light "
                  f"at infinity along its `direction`) (got {cls.shadow_map!r})")
    uniform_kinds = {p.name: p.kind for p in (cls.params if cls.uniforms is None else cls.uniforms)}
    wanted_kinds = {"light": "vec3", "falloff": "rgb"}
    bounds = cls.numerics_bounds
    if not isinstance(bounds, dict) or not all(piece in wanted_kinds and uniform_kinds.get(uniform) == wanted_kinds[piece]
                                               for piece, uniform in bounds.items()) \
            or ("falloff" in bounds and "light" not in bounds):
        raise err(f"{cls.__qualname__}.numerics_bounds must map 'light' to the kind's position uniform (vec3) and, with "
                  f"it, 'falloff' to its intensity uniform (rgb) (got {bounds!r})")
    needed = {"cube": "position", "ortho": "direction"}.get(cls.shadow_map)
    if needed and needed not in {p.name for p in cls.params}:
        raise err(f"{cls.__qualname__}.shadow_map = {cls.shadow_map!r} needs a parameter named {needed!r}")
    contract = cls.contract()
    wanted = " and ".join(f"`{f.glsl(name)}`" for f in contract)
    if cls.glsl is None:
        raise err(f"{cls.__qualname__} has no glsl: set glsl to the GLSL source of {wanted} or to a .glsl path")
    for function in contract:
        method = cls.__dict__.get(function.suffix)
        inherited = [c.__dict__.get(function.suffix) for c in cls.__mro__[1:-1] if c.__module__ != base.__module__
                     and not c.__dict__.get("abstract_contract", False)]
        if method is None and all(m is None for m in inherited):
            raise err(f"{cls.__qualname__} defines no numpy twin: add `def {function.suffix}(self, "
                      f"{', '.join(function.twin)})` returning {function.returns}, the same formulation as its GLSL")
        if method is not None:
            args = twin_arguments(method)
            if args is not None and len(args) != len(function.twin):
                raise err(f"{cls.__qualname__}.{function.suffix} must take (self, {', '.join(function.twin)}) "
                          f"(got ({', '.join(['self'] + [a.name for a in args])}))")
    _check_glsl(cls, strip_comments(cls.source()))
    for method in getattr(cls, "required_methods", ()):
        if all(c.__dict__.get(method) is None for c in cls.__mro__[:-1] if c.__module__ != base.__module__
               and not c.__dict__.get("abstract_contract", False)):
            raise err(f"{cls.__qualname__} defines no `{method}`: an extended kind gives its float64 exact integral, "
                      f"`def exact(self, x, n, p, integrand, clip=())` (glphong.twin.quadrature has polygons, spheres "
                      "and disks)")


def _check_glsl(cls, code):
    err, name = cls.definition_error, cls.name
    for function in cls.contract():
        if not re.search(function.pattern(name), code):
            found = re.search(rf"\b\w+\s+{name}_{function.suffix}\s*\([^)]*\)", code)
            raise err(f"{cls.__qualname__}.glsl must define `{function.glsl(name)}` (name = {name!r} gives the prefix); "
                      + (f"found `{found.group(0)}`" if found else f"found no {name}_{function.suffix}"))
    check_uniform_reads(cls, code, {p.name for p in cls.uniform_params()})
    own = check_library_clash(cls, code)
    unprefixed = sorted(n for n in own if not n.startswith(f"{name}_") and not n.upper().startswith(f"{name.upper()}_"))
    if unprefixed:
        raise err(f"{cls.__qualname__}.glsl defines {', '.join(unprefixed)} without the prefix {name}_ (lights and "
                  "materials share one program): prefix them")
