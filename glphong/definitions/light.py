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
import functools
import re
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.core.glsl_files import library_chunks
from glphong.definitions.cases import Case
from glphong.definitions.definition import Definition
from glphong.definitions.light_band import sensitivity_band
from glphong.definitions.light_checks import check_light_definition
from glphong.definitions.material import MaterialSum, bind_arguments
from glphong.definitions.params import DefinitionError, GlslFile, Param, ParamValues  # noqa: F401 - a kind's vocabulary
from glphong.definitions.registry import LIGHTS, MATERIALS, light_for_key, light_named, light_source, registered_lights

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


class LightModel(Definition):
    """One kind of light, defined the way the built-ins are (the definition mechanism of
    `glphong.definitions.definition.Definition`, which material models share).

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

    registry = LIGHTS
    #: where the kind comes in the shader's loop over kinds (the built-ins' order; None: after them, in definition
    #: order)
    loop_order = None

    @classmethod
    def check_unnamed(cls):
        """A subclass without a name of its own may not define GLSL or a twin (it would render as its parent)."""
        if "glsl" in cls.__dict__ or "incident" in cls.__dict__:
            raise LightDefinitionError(f"{cls.__qualname__} defines a light but no name: add name = '...' "
                                       "(a lowercase GLSL prefix)" if cls.name is None else
                                       f"{cls.__qualname__} redefines glsl or incident but keeps the name "
                                       f"{cls.name!r}: give it a name of its own")

    @classmethod
    def check_definition(cls):
        """The checks of `glphong.definitions.light_checks` (raising `LightDefinitionError`)."""
        check_light_definition(cls, LightModel)

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

    def exact_texels(self):
        """Directions the exact integral of a term without a closed form visits per pixel, where they grow with the
        light's data (`verify`'s sampling rule, `glphong.checks.method_sample.auto_sample_size`): 0 (default) where
        the cost is bounded; an environment light's texels."""
        return 0

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
        """Every parameter's validated value by name (dict), and ``shadows`` for a kind that casts shadows: the
        constructor's arguments, so ``type(light)(**light.parameter_values()) == light``."""
        values = {p.name: getattr(self, p.name) for p in self.params}
        return values | {"shadows": self.shadows} if self.shadow_map is not None else values

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
        return self.generic_band(x, p, constants)

    def generic_band(self, x, p, constants, base=None):
        """`band`'s generic default (`sensitivity_band` of the twin's irradiance); ``base``: the irradiance at ``(x,
        p)`` where the caller has it."""
        return sensitivity_band(lambda x_, p_: self.incident(x_, p_)[2], x, p, self.perturbed_uniforms(), constants,
                                base=None if base is None else np.broadcast_to(base, np.shape(x)))

    def band_given(self, x, p, constants, incident):
        """`band`, where ``incident`` = ``self.incident(x, p)`` is in hand (`glphong.checks.reference.incident_light`
        computes it for the twin): the generic band takes its value at ``(x, p)`` from it instead of computing it again;
        a kind with a `band` of its own computes that (it may override this too)."""
        if type(self).band is not LightModel.band:
            return self.band(x, p, constants)
        return self.generic_band(x, p, constants, incident[2])

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


# --------------------------------------------------------------------------- definition-time checks
@functools.cache
def _lecture_phong():
    """The lecture's Phong, ``Lambert + PhongLobe``, as a `MaterialSum` of the registered models 'lambert' and
    'phong_lobe' (the same terms as `glphong.Phong`, which lives in a layer above this one; made once)."""
    terms = (MATERIALS.named("lambert"), MATERIALS.named("phong_lobe"))
    return type("Phong", (MaterialSum,), {"terms": terms, "__module__": __name__})


def light_cases(light):
    """Generic stability geometry for one light (a `glphong.definitions.cases.Case` each): the light over a
    Lambert+Phong point at normal, oblique and grazing incidence of the point's normal."""
    name = type(light).name
    material = _lecture_phong()(0.3, 0.4, 20.0)
    out = []
    for label, normal in (("normal", (0.0, 0.0, 1.0)), ("oblique 60 deg", (0.0, np.sin(np.pi / 3), np.cos(np.pi / 3))),
                          ("grazing 89.9 deg", (0.0, np.sin(np.radians(89.9)), np.cos(np.radians(89.9))))):
        out.append(Case(f"{name} light, {label}", f"light {name}", material, normal=tuple(float(c) for c in normal),
                        eye=(0.3, 0.2, 2.0), lights=(light,)))
    return tuple(out)


class ExactIrradiance:
    """For a kind whose irradiance is a uniform itself, or one product or quotient of uniforms: its float32 error is
    inside the ``(1 +- A eps)`` every light term gets, so its band is its twin's value (mix in before `LightModel`)."""

    def band(self, x, p, constants):
        """The twin's value: exact beyond the term's ``A eps``."""
        e = self.incident(x, p)[2]
        return e, e

    def band_given(self, x, p, constants, incident):
        """The twin's value ``incident[2]``, in hand (`LightModel.band_given`)."""
        return incident[2], incident[2]


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
