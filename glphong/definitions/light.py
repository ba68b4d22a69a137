"""The light mechanism: a kind of light as an open definition (docs/design.md section 11).

One light kind is one `LightModel` subclass, the way one reflectance model is one
`glphong.materials.MaterialModel`: its parameters (`Param`, with units and ranges), its GLSL
function and its numpy twin, which give at a surface point ``x``

    whether the light reaches it (``valid``), the unit direction ``wi`` toward the light, and the
    irradiance ``E`` [W/m^2] on a surface facing it,

its error band (`LightModel.band`, a generic default), its extreme cases for the stability suite, and
its glTF and pyrender counterparts where they exist.  The lecture's light-emission slide in code: a
light is what it delivers toward a point.  The radiance one light adds is
``material_response(f, wi, wo, n.wi) * E`` where ``n.wi > 0`` and ``valid``.

The GLSL defines ``bool <name>_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)``, reading
light ``j``'s uniforms ``u_<name>_<param>[j]`` (arrays glphong declares, one entry per light of the
kind); the twin ``incident(self, x, p)`` returns ``(valid, wi, irradiance)`` from ``x`` ``(N, 3)`` and
``p``, the `ParamValues` of light ``j`` (the float32 values the GPU was given, and the kind's
structural defines in ``p.defines``).  Like the GLSL, the twin reads nothing but its arguments.

The built-in kinds (`glphong.lights.PointLight`, `UnattenuatedPointLight`, `DirectionalLight`,
`SpotLight`) are defined exactly this way.  A definition is checked when its class is created.
"""
import inspect
import re
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.core.glsl_files import library_chunks
from glphong.materials.cases import Case
from glphong.materials.model import bind_arguments
from glphong.materials.phong import Phong
from glphong.materials.params import (_GLSL_KEYWORDS, _IDENT, RESERVED_NAMES, DefinitionError, GlslFile,  # noqa: F401
                                      Param, ParamValues)
from glphong.materials.registry import (_library_names, _strip_comments, _top_level_names, hashed_source,
                                        registered_models)
from glphong.twin.band import EPS
from glphong.twin.functions import perpendiculars

__all__ = ["LightModel", "LightDefinitionError", "registered_lights", "light_named", "light_for_key",
           "light_cases", "light_source", "ExactIrradiance", "LIGHT_LIBRARY_CHUNKS", "Param", "GlslFile", "pose_pointing", "gltf_entry", "mp", "mp32", "mp_dot",
           "mp_toward", "mp_range_window"]

#: library chunks a light kind may use: ``lights`` (``point_irradiance``, ``range_window``), ``area`` (a polygon seen
#: from a point, after ``angle``) and the materials' ones
LIGHT_LIBRARY_CHUNKS = library_chunks("light")


@dataclass(frozen=True)
class ContractFunction:
    """One function a light kind defines twice, in GLSL (``<kind>_<suffix>``) and as its numpy twin (method
    ``suffix``): checked when the kind is defined.

    Attributes
    ----------
    suffix : str
    returns : str
        The GLSL return type (the twin's return value in words, for messages).
    arguments : tuple of str
        The GLSL parameters, e.g. ``('vec3 x', 'int j', 'out vec3 wi')``.
    twin : tuple of str
        The twin's arguments after ``self``.
    """

    suffix: str
    returns: str
    arguments: tuple
    twin: tuple

    def glsl(self, name):
        """The GLSL signature."""
        return f"{self.returns.split()[0]} {name}_{self.suffix}({', '.join(self.arguments)})"

    def pattern(self, name):
        """A regular expression matching the GLSL signature with any parameter names."""
        parts = [r"\s+".join(re.escape(w) for w in a.split()[:-1]) + r"\s+\w+" for a in self.arguments]
        return (rf"\b{self.returns.split()[0]}\s+{name}_{self.suffix}\s*\(\s*" + r"\s*,\s*".join(parts) + r"\s*\)")


#: a punctual kind's function: at a point, whether the light reaches it, its direction and the irradiance
INCIDENT = ContractFunction("incident", "bool (valid (N,) bool, wi (N, 3) unit vectors toward the light, irradiance "
                            "(N, 3) [W/m^2])", ("vec3 x", "int j", "out vec3 wi", "out vec3 irradiance"), ("x", "p"))


class LightDefinitionError(DefinitionError):
    """A `LightModel` definition is incomplete or inconsistent."""


_REGISTRY = {}
_SOURCES = {}
_BY_HASH = {}


def registered_lights():
    """Every defined light kind, built-in and user, in the order the shader loops over them (tuple):
    the built-ins (point, unattenuated, directional, spot), then user kinds in definition order."""
    return tuple(_REGISTRY.values())


def light_named(name):
    """The `LightModel` subclass registered as ``name`` (KeyError naming the defined kinds)."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise KeyError(f"no light kind is named {name!r} (defined: {', '.join(_REGISTRY)})") from None


def light_for_key(name, source_hash):
    """The light kind a program key's entry was made from (by name and source hash)."""
    cls = _BY_HASH.get((name, source_hash))
    if cls is None:
        cls = light_named(name)
        if cls.source_hash() != source_hash:
            raise KeyError(f"no definition of the light kind {name!r} has source hash {source_hash}")
    return cls


def light_source(cls):
    """``(text, label, first_line, source_hash)`` of a light kind's GLSL (cached per class)."""
    return hashed_source(cls, _SOURCES, _BY_HASH)


def light_cases(light):
    """Generic stability geometry for one light (a `glphong.materials.cases.Case` each): the light over a
    Lambert+Phong point at normal, oblique and grazing incidence of the point's normal."""
    name = type(light).name
    material = Phong(0.3, 0.4, 20.0)
    out = []
    for label, normal in (("normal", (0.0, 0.0, 1.0)), ("oblique 60 deg", (0.0, np.sin(np.pi / 3), np.cos(np.pi / 3))),
                          ("grazing 89.9 deg", (0.0, np.sin(np.radians(89.9)), np.cos(np.radians(89.9))))):
        out.append(Case(f"{name} light, {label}", f"light {name}", material, normal=tuple(float(c) for c in normal),
                        eye=(0.3, 0.2, 2.0), lights=(light,)))
    return tuple(out)


class LightModel:
    """One kind of light, defined the way the built-ins are.

    Class attributes a definition sets
    ----------------------------------
    name : str
        Lowercase GLSL prefix, unique among lights and materials: the GLSL defines ``<name>_incident`` and
        reads ``u_<name>_<uniform>[j]``; part of the program key.
    params : tuple of Param
        The constructor's arguments, in positional order (kinds 'scalar', 'rgb', 'vec3' for a position,
        'direction' for a unit vector).
    uniforms : tuple of Param or None
        What the GLSL reads, where it differs from `params` (a `PointLight` is given its power and its GLSL
        reads the intensity): each is an array ``u_<name>_<uniform>[NUM_<NAME>_LIGHTS]``, filled from
        `uniform_value`.  None: the params.
    glsl : str or GlslFile
        GLSL text or a ``.glsl`` path defining ``bool <name>_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)``.
    uses : tuple of str
        Library chunks it calls (`LIGHT_LIBRARY_CHUNKS`).
    in_uber : bool
        Compiled into every uber-shader (the lecture's kinds; default False: a kind joins the uber-shader of
        the scenes that have it).
    gltf_type : str or None
        The ``KHR_lights_punctual`` type it reads and writes (`from_gltf`, `to_gltf`).
    pyrender_type : str or None
        The pyrender light class it maps (`from_pyrender`, `to_pyrender`).
    numerics_bounds : dict
        The pieces of ``Renderer(numerics='auto')`` the kind's GLSL reads (glphong.shaders.numerics), each with the uniform
        its bound is taken over: ``'light'`` (the direction by ``plain_normalize`` under ``NAIVE_LIGHT``) with the
        kind's position, ``'falloff'`` (``point_irradiance`` under ``NAIVE_FALLOFF``) with its intensity [W/sr].
        Default empty: the kind's arithmetic is never specialised.
    shadow_map : {'cube', 'ortho'} or None
        How the kind's shadows are mapped (docs/design.md section 12): 'cube' for a light at a point (its
        ``position``: six faces around it), 'ortho' for a light at infinity (its ``direction``: one orthographic
        map); None: the kind casts no shadows.  Where set, the constructor takes ``shadows=False``.

    Methods a definition provides
    -----------------------------
    incident(self, x, p)
        The numpy twin of ``<name>_incident``: ``(valid (N,) bool, wi (N, 3), irradiance (N, 3))``.
    uniform_value(self, name)  (optional)
        The value of uniform ``name`` for this light (default: the parameter of that name).
    check(self)  (optional)
        Checks across parameters, raising ValueError (a spot light's inner cone inside its outer one).
    structural_defines(cls, lights)  (optional classmethod)
        ``(NAME, value)`` pairs the kind's chunk is compiled with for a scene's ``lights`` of the kind (each
        ``#define <KIND>_<NAME>``): what no light of the scene needs is left out.
    band(self, x, p, constants), stability_cases(cls)  (optional)
        As for materials: the irradiance's float32 error interval, extreme cases.
    oracle(self, x)  (optional)
        ``(wi, irradiance)`` in mpmath at the working precision, at ``x`` (a list of 3 mpf), from the light's
        own parameters (positions and values rounded to float32 with `mp32`, as the GPU receives them), or
        None where the light does not reach ``x`` (for `glphong.checks.stability`; default: the twin in float64).
    """

    name = None
    params = ()
    uniforms = None
    glsl = None
    uses = ()
    in_uber = False
    gltf_type = None
    pyrender_type = None
    shadow_map = None
    numerics_bounds = {}
    #: 'punctual' (one direction and irradiance per light and point) or 'extended' (`glphong.lights.ExtendedLight`)
    extent = "punctual"
    #: the light is the surroundings (an environment), which a term's occlusion darkens as it does the ambient light
    #: (glTF's occlusion texture; `glphong.materials.MaterialModel.occluded_by`)
    occludable = False
    #: uniform name -> entries per light, for a uniform that holds several values per light (a polygon's vertices):
    #: declared ``u_<name>_<uniform>[NUM_<NAME>_LIGHTS * n]``, light j's entries at ``j * n + i``; ``n`` an int, or
    #: the name of one of the kind's structural defines whose value it is (an environment map's texels: each light's
    #: entries padded with zeros to the scene's largest)
    uniform_lengths = {}
    #: scalar uniforms that hold exact small integers (a count, a sample knob): the generic band does not perturb them
    exact_uniforms = ()
    definition_error = LightDefinitionError
    definition_kind = "light"
    keywords = ()
    oracle = None
    #: ``(NAME, what)`` of each structural define `structural_defines` may give: what a program leaves out
    #: without it (listed by `glphong.describe`), and what the uber-shader always compiles
    optional_code = ()
    #: uniform name -> the structural define it exists under (declared inside ``#if defined(<KIND>_<NAME>)``)
    conditional_uniforms = {}

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "name" not in cls.__dict__:
            if "glsl" in cls.__dict__ or "incident" in cls.__dict__:
                raise LightDefinitionError(f"{cls.__qualname__} defines a light but no name: add name = '...' "
                                           "(a lowercase GLSL prefix)" if cls.name is None else
                                           f"{cls.__qualname__} redefines glsl or incident but keeps the name "
                                           f"{cls.name!r}: give it a name of its own")
            return
        existing = _REGISTRY.get(cls.name) if isinstance(cls.name, str) else None
        if existing is not None and existing is not cls:
            same = (existing.__module__, existing.__qualname__) == (cls.__module__, cls.__qualname__)
            if existing.__module__.startswith("glphong.") or not same:
                raise LightDefinitionError(f"{cls.__qualname__}: the light name {cls.name!r} is taken by "
                                           f"{existing.__module__}.{existing.__qualname__}; choose another name")
        _check_definition(cls)
        _REGISTRY[cls.name] = cls  # a re-run of the same definition (a notebook cell) replaces it

    def __init__(self, *args, shadows=False, **kwargs):
        if type(self).name is None:
            raise TypeError(f"{type(self).__name__} is not a light kind (it has no name)")
        for name, value in bind_arguments(type(self), type(self).params, args, kwargs).items():
            object.__setattr__(self, name, value)
        if not isinstance(shadows, (bool, np.bool_)):
            raise TypeError(f"shadows must be a bool, True or False (got {shadows!r})")
        if shadows and self.shadow_map is None:
            raise ValueError(f"{type(self).__name__} casts no shadows (its kind declares no shadow_map)")
        object.__setattr__(self, "shadows", bool(shadows))
        self.check()

    def check(self):
        """Checks across parameters (default none); raise ValueError naming them."""

    @classmethod
    def contract(cls):
        """The functions the kind defines in GLSL and as its twin (tuple of `ContractFunction`): a punctual kind's
        ``incident``."""
        return (INCIDENT,)

    # ---- identity
    @property
    def kind(self):
        """The kind's name (``'point'``, ``'spot'``, ...)."""
        return type(self).name

    def parameter_values(self):
        """Every parameter's validated value by name (dict), and ``shadows``."""
        return {p.name: getattr(self, p.name) for p in self.params} | {"shadows": self.shadows}

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable: make a new light instead of setting {name!r}")

    def __eq__(self, other):
        return type(other) is type(self) and other.parameter_values() == self.parameter_values()

    def __hash__(self):
        return hash((type(self), tuple(self.parameter_values().items())))

    def __repr__(self):
        optional = {p.name for p in self.params if p.optional}
        shown = [f"{k}={v!r}" for k, v in self.parameter_values().items()
                 if not (v is None and k in optional) and not (k == "shadows" and not v)
                 and not (k == "method" and v == "auto")]
        return f"{type(self).__name__}({', '.join(shown)})"

    # ---- what the program key and the uniforms are made of
    @classmethod
    def uniform_params(cls):
        """The uniforms the GLSL reads, as `Param` (`uniforms`, or `params`)."""
        return cls.params if cls.uniforms is None else cls.uniforms

    @classmethod
    def uniform_name(cls, uniform):
        """``u_<name>_<uniform>``."""
        return f"u_{cls.name}_{uniform}"

    def uniform_value(self, name):
        """The value of uniform ``name`` for this light (default: the parameter of that name)."""
        return getattr(self, name)

    @classmethod
    def key_integrals(cls, lights=()):
        """None for a punctual kind; an extended kind's closed forms for a scene's ``lights`` of it
        (`glphong.shaders.key.LightKey.integrals`)."""
        return None

    @classmethod
    def uniform_declarations(cls):
        """The GLSL declarations of the kind's uniform arrays, generated from `uniform_params`."""
        lines = []
        for p in cls.uniform_params():
            length = cls.uniform_lengths.get(p.name)
            length = f"{cls.name.upper()}_{length}" if isinstance(length, str) else length
            size = f"NUM_{cls.name.upper()}_LIGHTS" + (f" * {length}" if length else "")
            line = (f"uniform {p.glsl_type} {cls.uniform_name(p.name)}[{size}];  // {p.kind}"
                    f"{' in ' + p.interval if p.kind in ('scalar', 'rgb') else ''}{' [' + p.unit + ']' if p.unit else ''}")
            define = cls.conditional_uniforms.get(p.name)
            lines += [f"#if defined({cls.name.upper()}_{define})", line, "#endif"] if define else [line]
        return "\n".join(lines)

    @classmethod
    def active_uniforms(cls, defines=()):
        """The uniforms a program with the kind's structural ``defines`` (pairs) declares (tuple of Param)."""
        given = {name for name, _ in defines}
        return tuple(p for p in cls.uniform_params()
                     if cls.conditional_uniforms.get(p.name) is None or cls.conditional_uniforms[p.name] in given)

    @classmethod
    def source(cls):
        """The kind's GLSL text."""
        return light_source(cls)[0]

    @classmethod
    def source_hash(cls):
        """First 12 hex digits of the SHA-256 of the declarations, uses and GLSL text (part of the program key)."""
        return light_source(cls)[3]

    @classmethod
    def source_label(cls):
        """Where the GLSL comes from (a file, or the class), for compile errors."""
        return light_source(cls)[1]

    @classmethod
    def structural_defines(cls, lights):
        """``(NAME, value)`` defines of the kind's chunk for a scene's ``lights`` of this kind (default none)."""
        return ()

    @classmethod
    def pack_uniforms(cls, lights, defines=None):
        """The uniform arrays of ``lights`` (all of this kind), float32, by uniform name: (N, 3) or (N,); those a
        program with ``defines`` declares (default: the lights' own `structural_defines`)."""
        defines = cls.structural_defines(lights) if defines is None else defines
        out = {}
        for p in cls.active_uniforms(defines):
            length = cls.uniform_length(p.name, defines)
            values = [_validate.float32_uniform(light.uniform_value(p.name)) for light in lights]
            if length is not None:  # each light's entries, padded with zeros to the declared length
                values = [np.concatenate([v, np.zeros((length - len(v),) + v.shape[1:], np.float32)]) for v in values]
            values = np.array(values, dtype=np.float32)
            out[cls.uniform_name(p.name)] = values.reshape((-1,) + values.shape[2:]) if length is not None else values
        return out

    @classmethod
    def uniform_length(cls, name, defines=()):
        """Entries per light of uniform ``name`` (`uniform_lengths`; a define's value where it names one), or None
        for one entry."""
        length = cls.uniform_lengths.get(name)
        if isinstance(length, str):
            given = dict(defines)
            if length not in given:
                raise KeyError(f"{cls.__qualname__}.uniform_lengths[{name!r}] names the structural define {length!r}, "
                               "which structural_defines did not give")
            return int(given[length])
        return length

    @classmethod
    def usage_defines(cls, defines, uses):
        """Defines a program adds to the kind's structural ``defines`` (pairs) from what its terms ``uses`` of an
        extended kind ('irradiance', 'lobe', 'sample'): where they condition uniforms (`conditional_uniforms`), a
        program declares and is given only what it reads (default none)."""
        return ()

    @classmethod
    def values_from_uniforms(cls, uniforms, j, dtype=np.float64, defines=()):
        """`ParamValues` of light ``j`` from a program's uniforms, in ``dtype``, with ``defines`` (pairs) as the dict
        ``p.defines``."""
        def entry(p):
            array = uniforms[cls.uniform_name(p.name)]
            n = cls.uniform_length(p.name, defines)
            return array[j] if n is None else array[j * n:(j + 1) * n]

        values = {p.name: np.asarray(entry(p), dtype=dtype) for p in cls.active_uniforms(defines)}
        return ParamValues(values | {"defines": dict(defines)})

    def values(self, dtype=np.float64):
        """`ParamValues` of this light alone (its float32 uniforms in ``dtype``; defines as for itself)."""
        defines = self.structural_defines([self])
        defines = tuple(defines) + tuple(self.usage_defines(defines, ("irradiance", "lobe", "sample")))
        return self.values_from_uniforms(self.pack_uniforms([self], defines), 0, dtype, defines)

    @classmethod
    def twin(cls):
        """An instance to call the twin on: the twin reads only ``x`` and ``p``, like the GLSL."""
        return object.__new__(cls)

    # ---- the twin and what is built on it
    def incident(self, x, p):
        """The numpy twin of ``<name>_incident``: ``(valid, wi, irradiance)``."""
        raise NotImplementedError

    def band(self, x, p, constants):
        """Interval ``(low, high)``, each (N, 3), of the float32 irradiance beyond the ``(1 +- A eps)`` every
        light term is widened by (`glphong.checks.tolerances.point_band`).

        The generic default: the twin's first-order sensitivity to its inputs, each perturbed by a few ulps
        as float32 arithmetic perturbs them: ``x`` and every 'vec3' uniform scaled componentwise by
        ``1 +- D eps`` (which covers the rounding of ``position - x``), every 'direction' rotated by
        ``D eps`` about two axes, every scalar and rgb uniform scaled by ``1 +- A eps``; the deviations
        add up worst-case.  The built-in kinds whose only error is that of a product or quotient return
        the twin's value (their error is inside the term's ``A eps``).
        """
        return sensitivity_band(lambda x_, p_: self.incident(x_, p_)[2], x, p, self.perturbed_uniforms(), constants)

    @classmethod
    def perturbed_uniforms(cls):
        """The uniforms the generic band perturbs: all but `exact_uniforms` (tuple of Param)."""
        return tuple(p for p in cls.uniform_params() if p.name not in cls.exact_uniforms)

    @classmethod
    def example(cls, **overrides):
        """An instance at representative values (`Param.example`), with ``overrides``."""
        return cls(**{p.name: p.example() for p in cls.params if not p.optional} | overrides)

    @classmethod
    def stability_cases(cls):
        """The kind's extreme cases for `glphong.checks.stability` (default: `light_cases` of `example`)."""
        return light_cases(cls.example())

    # ---- counterparts in files and other renderers (None: none)
    @classmethod
    def from_gltf(cls, value, entry, pose):
        """This kind from a ``KHR_lights_punctual`` light of type `gltf_type`: ``value`` (3,) its ``color`` times
        ``intensity`` in W/sr (positional kinds) or W/m^2 (directional), units already converted; ``entry``
        the validated JSON light (its ``range``, ``spot``); ``pose`` (4, 4) its node's world transform (the
        light at the origin, pointing along -z)."""
        raise NotImplementedError

    def to_gltf(self):
        """``(entry, pose)``: the ``KHR_lights_punctual`` light (radiometric values, `gltf_entry`) and its node's
        pose (4, 4), or None where glTF has no place for this kind."""
        return None

    @classmethod
    def from_pyrender(cls, value, light, pose):
        """This kind from a pyrender light of class `pyrender_type`: ``value`` (3,) its ``color * intensity``,
        ``light`` the pyrender light, ``pose`` (4, 4) its node's world transform."""
        raise NotImplementedError

    def to_pyrender(self, pyrender):
        """``(light, pose)``: the light of the ``pyrender`` module and its node pose (4, 4), or None where pyrender
        has no equivalent."""
        return None


def sensitivity_band(evaluate, x, p, params, constants, directions=()):
    """The generic band: ``evaluate(x, p, *directions)`` (N, 3) and its first-order sensitivity to its inputs, each
    perturbed by a few ulps as float32 arithmetic perturbs them, added worst-case (`LightModel.band`).

    ``x`` (N, 3) and every 'vec3' uniform of ``params`` are scaled componentwise by ``1 +- D eps`` (each entry of a
    uniform with several per light), every 'direction' uniform and each of ``directions`` ((N, 3) unit vectors: a
    normal, a reflected view) rotated by ``D eps`` about two axes, every scalar and rgb uniform scaled by
    ``1 +- A eps``.  Returns ``(low, high)``, each (N, 3).
    """
    base = np.asarray(evaluate(x, p, *directions), dtype=np.float64)
    up, down = np.zeros_like(base), np.zeros_like(base)

    def add(x_, p_, dirs):
        with np.errstate(all="ignore"):
            delta = np.nan_to_num(np.asarray(evaluate(x_, p_, *dirs), dtype=np.float64) - base, nan=0.0)
        np.maximum(up, delta, out=up)
        np.minimum(down, delta, out=down)

    d = constants.D * EPS
    for axis in range(3):
        for sign in (1.0, -1.0):
            moved = np.array(x, dtype=np.float64)
            moved[:, axis] *= 1.0 + sign * d
            add(moved, p, directions)
    for i, v in enumerate(directions):
        for axis in perpendiculars(v):
            for s in (1, -1):
                turned = v + s * d * axis
                add(x, p, directions[:i] + (turned / np.linalg.norm(turned, axis=-1, keepdims=True),) + directions[i + 1:])
    for param in params:
        value = np.asarray(getattr(p, param.name), dtype=np.float64)
        variants = []
        if param.kind == "vec3":
            for index in np.ndindex(value.shape):
                for s in (1, -1):
                    moved = value.copy()
                    moved[index] *= 1.0 + s * d
                    variants.append(moved)
        elif param.kind == "direction":
            variants = [(value + s * d * axis) / np.linalg.norm(value + s * d * axis)
                        for axis in perpendiculars(value) for s in (1, -1)]
        else:
            variants = [value * (1.0 + s * constants.A * EPS) for s in (1, -1)]
        for v in variants:
            add(x, ParamValues({**p.__dict__, param.name: v}), directions)
    return base + down, base + up


# --------------------------------------------------------------------------- definition-time checks
def _check_definition(cls):
    """The definition-time checks of a `LightModel` subclass; raises LightDefinitionError."""
    err = LightDefinitionError
    name = cls.name
    if not isinstance(name, str) or not _IDENT.match(name) or "__" in name or name.endswith("_"):
        raise err(f"{cls.__qualname__}.name must be a lowercase GLSL identifier such as 'luminaire' (got {name!r})")
    builtin = cls.__module__.startswith("glphong.")
    if not builtin and (name in RESERVED_NAMES or name in _GLSL_KEYWORDS or name.startswith("gl_")):
        raise err(f"{cls.__qualname__}.name {name!r} is reserved by glphong's shading code or GLSL; choose another")
    clash = [m for m in registered_models() if m.name == name]
    if clash:
        raise err(f"{cls.__qualname__}.name {name!r} is the name of the material model "
                  f"{clash[0].__module__}.{clash[0].__qualname__} (their uniforms u_{name}_* would clash); choose another")
    for attr in ("params", "uniforms"):
        value = getattr(cls, attr)
        if attr == "uniforms" and value is None:
            continue
        if not isinstance(value, tuple) or not all(isinstance(p, Param) for p in value):
            raise err(f"{cls.__qualname__}.{attr} must be a tuple of glphong.materials.Param")
        names = [p.name for p in value]
        if len(set(names)) != len(names):
            raise err(f"{cls.__qualname__}.{attr} repeats a name ({names})")
        if any(p.textureable for p in value):
            raise err(f"{cls.__qualname__}.{attr}: a light's parameters are constants (textureable is for materials)")
    shadowing = sorted({p.name for p in cls.params} & set(dir(LightModel)))
    if shadowing:
        raise err(f"{cls.__qualname__}.params: {', '.join(shadowing)} would shadow a LightModel attribute; "
                  "choose other parameter names")
    if not isinstance(cls.uses, tuple) or not set(cls.uses) <= set(LIGHT_LIBRARY_CHUNKS):
        raise err(f"{cls.__qualname__}.uses must be a tuple of library chunks "
                  f"{', '.join(map(repr, LIGHT_LIBRARY_CHUNKS))} (got {cls.uses!r})")
    if cls.uniforms is not None and "uniform_value" not in {k for c in cls.__mro__[:-1] if c is not LightModel
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
        inherited = [c.__dict__.get(function.suffix) for c in cls.__mro__[1:-1] if c.__module__ != __name__
                     and not c.__dict__.get("abstract_contract", False)]
        if method is None and all(m is None for m in inherited):
            raise err(f"{cls.__qualname__} defines no numpy twin: add `def {function.suffix}(self, "
                      f"{', '.join(function.twin)})` returning {function.returns}, the same formulation as its GLSL")
        if method is not None:
            try:
                args = [a for a in list(inspect.signature(method).parameters.values())[1:]
                        if a.kind in (a.POSITIONAL_ONLY, a.POSITIONAL_OR_KEYWORD)]
            except (TypeError, ValueError):
                args = None
            if args is not None and len(args) != len(function.twin):
                raise err(f"{cls.__qualname__}.{function.suffix} must take (self, {', '.join(function.twin)}) "
                          f"(got ({', '.join(['self'] + [a.name for a in args])}))")
    _SOURCES.pop(cls, None)
    _check_glsl(cls, _strip_comments(light_source(cls)[0]))
    for method in getattr(cls, "required_methods", ()):
        if all(c.__dict__.get(method) is None for c in cls.__mro__[:-1] if c.__module__ != __name__
               and not c.__dict__.get("abstract_contract", False)):
            raise err(f"{cls.__qualname__} defines no `{method}`: an extended kind gives its float64 exact integral, "
                      f"`def exact(self, x, n, p, integrand, clip=())` (glphong.twin.quadrature has polygons, spheres "
                      "and disks)")


def _check_glsl(cls, code):
    err, name = LightDefinitionError, cls.name
    for function in cls.contract():
        if not re.search(function.pattern(name), code):
            found = re.search(rf"\b\w+\s+{name}_{function.suffix}\s*\([^)]*\)", code)
            raise err(f"{cls.__qualname__}.glsl must define `{function.glsl(name)}` (name = {name!r} gives the prefix); "
                      + (f"found `{found.group(0)}`" if found else f"found no {name}_{function.suffix}"))
    read = set(re.findall(rf"\bu_{name}_([A-Za-z_]\w*)", code))
    declared = {p.name for p in cls.uniform_params()}
    if read - declared:
        raise err(f"{cls.__qualname__}.glsl reads {', '.join(f'u_{name}_{x}' for x in sorted(read - declared))}, "
                  f"which no uniform declares (uniforms: {', '.join(sorted(declared)) or 'none'})")
    if declared - read:
        raise err(f"{cls.__qualname__}.glsl never reads {', '.join(f'u_{name}_{x}' for x in sorted(declared - read))}: "
                  "every uniform is an array the light function must use (or remove it)")
    if re.search(rf"\buniform\s+\w+\s+u_{name}_", code):
        raise err(f"{cls.__qualname__}.glsl declares its own u_{name}_* uniforms: glphong declares them (arrays "
                  f"of NUM_{name.upper()}_LIGHTS) from its uniforms; remove the declarations")
    own = _top_level_names(code)
    clash = own & _library_names()
    if clash:
        raise err(f"{cls.__qualname__}.glsl defines {', '.join(sorted(clash))}, which glphong's library chunks "
                  f"define; prefix your functions with {name}_")
    unprefixed = sorted(n for n in own if not n.startswith(f"{name}_") and not n.upper().startswith(f"{name.upper()}_"))
    if unprefixed:
        raise err(f"{cls.__qualname__}.glsl defines {', '.join(unprefixed)} without the prefix {name}_ (lights and "
                  "materials share one program): prefix them")


class ExactIrradiance:
    """For a kind whose irradiance is a uniform itself, or one product or quotient of uniforms: its float32 error is
    inside the ``(1 +- A eps)`` every light term gets, so its band is its twin's value (mix in before `LightModel`)."""

    def band(self, x, p, constants):
        """The twin's value: exact beyond the term's ``A eps``."""
        e = self.incident(x, p)[2]
        return e, e


# --------------------------------------------------------------------------- shared by the kinds' oracles
def mp():
    """The ``mpmath`` module, imported when an oracle first runs: only the stability suite evaluates oracles, and
    ``import glphong`` does not pay for mpmath (the materials' oracles import it the same way)."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    return mpmath


def mp32(values):
    """``values`` (a number or a sequence) rounded to float32, as a list of mpmath numbers (one number: a list of 1)."""
    return [mp().mpf(float(np.float32(v))) for v in np.ravel(np.asarray(values, dtype=np.float64))]


def mp_dot(a, b):
    """``a . b`` of two lists of mpmath numbers."""
    return sum(x * y for x, y in zip(a, b))


def mp_toward(position, x):
    """``(unit vector from x toward position, distance)`` in mpmath, or ``(None, 0)`` where they coincide."""
    to = [a - b for a, b in zip(position, x)]
    d = mp().sqrt(mp_dot(to, to))
    return (None, d) if d == 0 else ([c / d for c in to], d)


def mp_range_window(d, range_):
    """``clamp(1 - (d/range)^4, 0, 1)`` in mpmath (1 for no range)."""
    return mp().mpf(1) if range_ is None else min(max(1 - (d / mp().mpf(range_)) ** 4, 0), 1)


# --------------------------------------------------------------------------- shared by the kinds' counterparts
def pose_pointing(direction, position=(0.0, 0.0, 0.0)):
    """A rigid pose (4, 4) at ``position`` whose -z axis is the unit ``direction``: how glTF and pyrender
    orient directional and spot lights."""
    z = -np.asarray(direction, dtype=np.float64)
    x = np.cross((0.0, 1.0, 0.0) if abs(z[1]) < 0.9 else (1.0, 0.0, 0.0), z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    pose[:3, 3] = position
    return pose


def gltf_entry(kind, values, **extra):
    """A ``KHR_lights_punctual`` light of type ``kind`` carrying RGB ``values`` as ``color`` (peak 1) times
    ``intensity`` (the peak), with ``extra`` keys."""
    values = np.asarray(values, dtype=np.float64)
    peak = float(values.max())
    return {"type": kind, "color": [float(c) for c in (values / peak if peak > 0 else np.ones(3))],
            "intensity": peak, **extra}
