"""The parts a material model is declared with: `Param` (a uniform with kind, range, unit, default),
`Choice` (a compile-time switch), `Properties` (what the model declares of itself), `ParamValues`,
`GlslFile` (a built-in model's shader file) and the naming rules they share.

docs/design.md section 8 describes the contract these serve.
"""
import keyword
import re
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.core.glsl_files import library_chunks
from glphong.twin.functions import ShadingFrame
from glphong.definitions.surface import SurfaceInput

__all__ = ["Param", "Choice", "Properties", "ParamValues", "ShadingFrame", "GlslFile", "DefinitionError", "MaterialDefinitionError",
           "KINDS", "NEEDS", "LIBRARY_CHUNKS", "RESERVED_NAMES", "MATERIAL_KEYWORDS"]

#: parameter kinds and their GLSL types: a float, an RGB triple, a point (``vec3``, any finite 3-vector, e.g. a
#: position [m]) and a direction (any non-zero 3-vector, normalised when validated)
KINDS = {"scalar": "float", "rgb": "vec3", "vec3": "vec3", "direction": "vec3"}
#: what a model may ask for beyond the normal and the light direction
NEEDS = ("view", "tangent", "uv")
#: library chunks (glsl/<name>.glsl) a model may use besides common.glsl, which is always there (in the order of
#: `glphong.core.glsl_files.LIBRARY`)
LIBRARY_CHUNKS = library_chunks("model")
#: names a model may not take: GLSL prefixes and uniforms of the shading loop and the library
RESERVED_NAMES = frozenset({
    "material", "shade", "common", "lights", "light", "point", "unattenuated", "directional", "ambient",
    "eye", "model", "normal", "view", "use", "ka", "safe", "lobe", "srgb", "encode", "mesh", "uber", "naive",
    "frame", "gl", "object", "exposure", "radiance", "fullscreen", "fresnel", "microfacet", "normal_map", "alpha_mask",
    "alpha_blend"})
#: material-level keywords every material takes
MATERIAL_KEYWORDS = ("ka", "two_sided", "normal_map", "alpha_mask", "alpha_blend")
_GLSL_KEYWORDS = frozenset("""attribute const uniform varying layout centroid flat smooth noperspective break continue
do for while switch case default if else in out inout float int void bool true false invariant discard return mat2
mat3 mat4 vec2 vec3 vec4 ivec2 ivec3 ivec4 bvec2 bvec3 bvec4 uint uvec2 uvec3 uvec4 lowp mediump highp precision
sampler2D struct common partition active asm class union enum typedef template this packed goto inline noinline
volatile public static extern external interface long short double half fixed unsigned superp input output
filter sizeof cast namespace using""".split())
_IDENT = re.compile(r"^[a-z][a-z0-9_]*$")


class DefinitionError(TypeError):
    """A definition (a material model, a light kind) is incomplete or inconsistent."""


class MaterialDefinitionError(DefinitionError):
    """A `MaterialModel` or `MaterialSum` definition is incomplete or inconsistent."""


# --------------------------------------------------------------------------- parameters
def _check_argument_name(kind, name):
    """A `Param` or `Table` name: a lowercase identifier, not a GLSL or Python keyword, not a material keyword."""
    if not isinstance(name, str) or not _IDENT.match(name) or name in _GLSL_KEYWORDS or keyword.iskeyword(name):
        raise MaterialDefinitionError(f"{kind} name must be a lowercase identifier such as 'kd' (got {name!r})")
    if name in MATERIAL_KEYWORDS:
        raise MaterialDefinitionError(f"{kind} {name!r}: the name is a keyword every material takes "
                                      f"({', '.join(MATERIAL_KEYWORDS)}); choose another")


@dataclass(frozen=True)
class Param:
    """One parameter of a material model.

    Parameters
    ----------
    name : str
        Python keyword and GLSL suffix: the uniform is ``u_<model>_<name>``.
    kind : {'scalar', 'rgb', 'vec3', 'direction'}
        A float, an RGB triple (a scalar broadcasts to the three channels), a point (any finite 3-vector;
        give ``low=-numpy.inf``) or a direction (any non-zero 3-vector, stored normalised).
    low, high : float, optional
        The valid range; at least one must be given (pass ``low=-numpy.inf`` explicitly for a
        parameter with no lower bound).  Values must also be finite and representable in float32.
    default : float or (3,) array_like, optional
        Value when the parameter is not passed; without one the parameter is required.
    unit : str
        Physical unit, for documentation (``'1/sr'``, ``'rad'``, ``''`` for dimensionless).
    doc : str
        One line of documentation.
    low_inclusive, high_inclusive : bool
        Whether the ends of the range are allowed values.
    textureable : bool
        The parameter also takes a `glphong.definitions.surface.SurfaceInput` (a texture, vertex
        colours or both, `glphong.Texture`, `glphong.VertexColors`): its value then varies over the
        surface, and the model's GLSL reads ``u_<model>_<name>`` unchanged (glphong sets it per fragment
        before the response is called).  rgb and scalar parameters; a scalar's input reads one channel
        (``channel='r'``, ``'g'`` or ``'b'``).
    optional : bool
        None is a valid value, and the default (a light's ``range=None``: no range).  The definition
        says what its uniform holds then (`glphong.lights.LightModel.uniform_value`).
    """

    name: str
    kind: str
    low: float = None
    high: float = None
    default: object = None
    unit: str = ""
    doc: str = ""
    low_inclusive: bool = True
    high_inclusive: bool = True
    textureable: bool = False
    optional: bool = False

    def __post_init__(self):
        _check_argument_name("Param", self.name)
        if self.kind not in KINDS:
            raise MaterialDefinitionError(f"Param {self.name!r}: kind must be one of {', '.join(map(repr, KINDS))} "
                                          f"(got {self.kind!r})")
        if self.textureable and self.kind not in ("rgb", "scalar"):
            raise MaterialDefinitionError(f"Param {self.name!r}: only rgb and scalar parameters can be textureable (a "
                                          "texture gives rgb per fragment, or one channel of it)")
        if self.low is None and self.high is None:
            raise MaterialDefinitionError(
                f"Param {self.name!r} has no range: give low= and/or high= (for example low=0.0); "
                "pass low=-numpy.inf explicitly for a parameter without bounds")
        low = -np.inf if self.low is None else float(self.low)
        high = np.inf if self.high is None else float(self.high)
        if np.isnan(low) or np.isnan(high) or not low < high:
            raise MaterialDefinitionError(f"Param {self.name!r}: low must be below high (got {self.low!r}, {self.high!r})")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)
        if self.default is not None:
            try:
                object.__setattr__(self, "default", self.validate(self.default))
            except (TypeError, ValueError) as exc:
                raise MaterialDefinitionError(f"Param {self.name!r}: default is not a valid value: {exc}") from None

    @property
    def glsl_type(self):
        """``'float'`` or ``'vec3'``."""
        return KINDS[self.kind]

    @property
    def interval(self):
        """The valid range as text, e.g. ``'[0, 2]'``."""
        return (f"{'[' if self.low_inclusive else '('}{self.low:g}, {self.high:g}"
                f"{']' if self.high_inclusive else ')'}")

    def validate(self, value):
        """``value`` checked against kind and range: a float, or a tuple of 3 floats for 'rgb'.

        Raises
        ------
        TypeError, ValueError
            Naming the parameter and its valid range.
        """

        if isinstance(value, SurfaceInput):
            return self._validate_surface_input(value)
        if value is None and self.optional:
            return None
        if self.kind == "vec3":
            return _validate.vec3(self.name, value)
        if self.kind == "direction":
            return _validate.unit_vec3(self.name, value)
        # an infinite end means "as far as float32 goes"; a finite one beyond FLT_MAX (a light's power, 4 pi
        # FLT_MAX, of which the GPU receives the intensity) is kept
        low = self.low if np.isfinite(self.low) else -_validate.FLT_MAX
        high = self.high if np.isfinite(self.high) else _validate.FLT_MAX
        low_inclusive = self.low_inclusive or self.low < -_validate.FLT_MAX
        high_inclusive = self.high_inclusive or self.high > _validate.FLT_MAX
        if self.kind == "rgb":
            return _validate.rgb(self.name, value, low=low, high=high, low_inclusive=low_inclusive,
                                 high_inclusive=high_inclusive)
        return _validate.scalar(self.name, value, low=low, high=high, low_inclusive=low_inclusive,
                                high_inclusive=high_inclusive)

    def _validate_surface_input(self, value):
        """A `SurfaceInput` given to this parameter: allowed where textureable, its values over any surface
        (texels times ``scale``; vertex colours in [0, 1]) within the range."""
        if not self.textureable:
            raise TypeError(f"{self.name} takes a constant ({self.kind} in {self.interval}), not a texture or vertex "
                            "colours: the model does not declare it textureable")
        if self.kind == "scalar" and value.channel is None:
            raise ValueError(f"{self.name} is a scalar: its texture or vertex colours need the channel it reads "
                             f"(channel='r', 'g' or 'b'; got {value!r})")
        if self.kind == "rgb" and value.channel is not None:
            raise ValueError(f"{self.name} is rgb: it reads all three channels (give channel=None; got {value!r})")
        low, high = value.value_range()
        below = self.low > -np.inf and (np.any(low < self.low) or not self.low_inclusive and np.any(low == self.low))
        above = self.high < np.inf and (np.any(high > self.high) or not self.high_inclusive and np.any(high == self.high))
        if below or above:
            raise ValueError(f"{self.name} must be in {self.interval} everywhere; {value!r} spans "
                             f"[{float(np.min(low)):g}, {float(np.max(high)):g}] (texels times scale"
                             f"{', vertex colours in [0, 1]' if value.vertex_colors else ''})")
        return value

    def example(self):
        """A representative valid value: the default, else 0.5 moved into the range."""
        if self.default is not None or self.optional:
            return self.default
        if self.kind in ("vec3", "direction"):
            return self.validate((0.0, 0.0, 1.0) if self.kind == "vec3" else (0.0, 0.0, -1.0))
        x = min(max(0.5, self.low), self.high)
        if x == self.low and not self.low_inclusive or x == self.high and not self.high_inclusive:
            x = self.low + 0.5 * (self.high - self.low) if np.isfinite(self.high - self.low) else \
                (self.low + 1.0 if np.isfinite(self.low) else self.high - 1.0)
        return self.validate(x)


@dataclass(frozen=True)
class Choice:
    """A structural option of a material model: which form of its formula the program compiles.

    Parameters
    ----------
    name : str
        Python keyword; the define is ``<MODEL>_<NAME>`` (upper-cased), its value the index of the
        chosen value in `values` (so the GLSL reads ``#if COOK_TORRANCE_LOBE_FORM == 1``).
    values : tuple of str
        The allowed values, in index order.
    default : str
    doc : str
    """

    name: str
    values: tuple
    default: str
    doc: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not _IDENT.match(self.name) or keyword.iskeyword(self.name):
            raise MaterialDefinitionError(f"Choice name must be a lowercase identifier (got {self.name!r})")
        if not isinstance(self.values, tuple) or not self.values or not all(isinstance(v, str) for v in self.values):
            raise MaterialDefinitionError(f"Choice {self.name!r}: values must be a non-empty tuple of str")
        if self.default not in self.values:
            raise MaterialDefinitionError(f"Choice {self.name!r}: default {self.default!r} is not one of {self.values}")

    @property
    def interval(self):
        return " or ".join(map(repr, self.values))

    def validate(self, value):
        """``value`` if it is one of `values`, else ValueError naming them."""
        if not isinstance(value, str) or value not in self.values:
            raise ValueError(f"{self.name} must be {self.interval} (got {value!r})")
        return value

    def define(self, value):
        """``(NAME, index)`` of the chosen value."""
        return self.name.upper(), str(self.values.index(value))


@dataclass(frozen=True)
class Properties:
    """What a model declares about its BRDF, for the analysis to check (docs/design.md section 8).

    Attributes
    ----------
    reciprocal, isotropic : bool or None
        ``f_r(wi, wo) = f_r(wo, wi)``; invariance under rotation about the normal.  None: not declared.
    energy_conserving : bool or None
        Directional albedo at most 1 for every incident direction, under `condition`.
    condition : str
        When energy conservation holds, e.g. ``'pi kd + ks (q + 2)/(2 pi) <= 1'``; '' for always/never.
    non_negative : bool or None
    """

    reciprocal: bool = None
    isotropic: bool = None
    energy_conserving: bool = None
    condition: str = ""
    non_negative: bool = True


class ParamValues:
    """The float32 parameter values the GPU was given, as attributes (``p.kd``, ``p.q``).

    rgb parameters are ``(3,)`` arrays, scalars ``()`` arrays, in the dtype of the computation
    (float64 in the reference: exactly the float32 values).
    """

    def __init__(self, values):
        self.__dict__.update(values)

    def __repr__(self):
        return "ParamValues(" + ", ".join(f"{k}={np.asarray(v).tolist()}" for k, v in self.__dict__.items()) + ")"


# --------------------------------------------------------------------------- GLSL sources
@dataclass(frozen=True)
class GlslFile:
    """A built-in model's GLSL file, relative to glphong's shader folder (``glsl/``).

    Read through the same root as every chunk, so ``GLPHONG_GLSL_DIR`` (a working copy of the
    shaders) applies to model chunks too.  A model's GLSL is read when its class is defined (the
    definition is checked then), library chunks when first used: set ``GLPHONG_GLSL_DIR`` before
    importing glphong.

    ``before``: further files of the shader folder whose text precedes the file's in the model's chunk, in order
    (`GltfPBR`'s extensions kept in their own files, each under its structural define); a compile error's line
    counts from the first of them.
    """

    path: str
    before: tuple = ()


