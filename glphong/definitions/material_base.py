"""What every material is: a sum of terms with a constant ``k_a``, sidedness, a normal map and an alpha mask
(`Material`), and the helpers the material sorts share: binding a constructor's arguments to its parameters
(`bind_arguments`), a surface input's define (`surface_define`) and a value's constant part (`constant_part`).
"""
import numpy as np

from glphong.core import validate as _validate
from glphong.definitions.params import MATERIAL_KEYWORDS, Param, Properties
from glphong.definitions.surface import AlphaBlend, AlphaMask, NormalMap
from glphong.definitions.table import Table

__all__ = ["Material", "bind_arguments", "surface_define", "constant_part"]


class Material:
    """Base of everything `glphong.Scene.add` accepts: a sum of terms, a constant ``k_a``, sidedness.

    Subclass `MaterialModel` (one term) or `MaterialSum` (several), never this class directly.

    Attributes
    ----------
    ka : tuple of 3 float
        Constant radiance ``k_a`` [W/(m^2 sr)] (the lecture's ambient term), >= 0.
    two_sided : bool
        Shade back faces with the normal flipped toward the viewer.
    normal_map : glphong.NormalMap or None
        A tangent-space normal map: every term shades with the mapped normal.
    alpha_mask : glphong.AlphaMask or None
        Alpha testing: fragments whose alpha is below the cutoff are not drawn.
    alpha_blend : glphong.AlphaBlend or None
        Alpha blending: the surface is composited over what lies behind it, per pixel in depth order.
    """

    #: display name; a model's name is also its GLSL prefix
    name = None
    #: declared BRDF properties (for a sum: derived from its terms unless declared)
    properties = Properties()

    def _set_common(self, ka, two_sided, normal_map=None, alpha_mask=None, alpha_blend=None):
        object.__setattr__(self, "ka", _validate.rgb("ka", ka))
        if not isinstance(two_sided, (bool, np.bool_)):
            raise TypeError(f"two_sided must be a bool, True or False (got {two_sided!r})")
        object.__setattr__(self, "two_sided", bool(two_sided))
        if normal_map is not None and not isinstance(normal_map, NormalMap):
            raise TypeError(f"normal_map must be a glphong.NormalMap or None (got {type(normal_map).__name__})")
        object.__setattr__(self, "normal_map", normal_map)
        if alpha_mask is not None and not isinstance(alpha_mask, AlphaMask):
            raise TypeError(f"alpha_mask must be a glphong.AlphaMask or None (got {type(alpha_mask).__name__})")
        object.__setattr__(self, "alpha_mask", alpha_mask)
        if alpha_blend is not None and not isinstance(alpha_blend, AlphaBlend):
            raise TypeError(f"alpha_blend must be a glphong.AlphaBlend or None (got {type(alpha_blend).__name__})")
        if alpha_blend is not None and alpha_mask is not None:
            raise ValueError("a material has an alpha mask or alpha blending, not both (glTF's alphaMode is one of "
                             "OPAQUE, MASK and BLEND)")
        object.__setattr__(self, "alpha_blend", alpha_blend)

    @property
    def components(self):
        """The material's terms, as `MaterialModel` instances (tuple)."""
        raise NotImplementedError

    def parameter_values(self):
        """Every parameter's validated value by name (dict), ``ka`` and ``two_sided`` included."""
        out = {}
        for term in self.components:
            out.update({a.name: getattr(term, a.name) for a in term.arguments()})
        out.update(ka=self.ka, two_sided=self.two_sided, normal_map=self.normal_map, alpha_mask=self.alpha_mask,
                   alpha_blend=self.alpha_blend)
        return out

    def uniform_values(self, key):
        """The material's uniforms for a program ``key``, as float32 arrays.

        Parameters
        ----------
        key : glphong.shaders.key.ProgramKey

        Returns
        -------
        dict of str to numpy.ndarray
            ``u_ka`` where the key has it, and ``u_<model>_<param>`` of the key's terms: every
            parameter of a term in the light loop (its tables as `TableData`), the ambient
            parameter of a term that only answers ``L_a``.
        """
        values = {}
        if key.has_ka:
            values["u_ka"] = _validate.float32_uniform(self.ka)
        values.update(self.surface_uniform_values(key))
        by_name = {term.name: term for term in self.components}
        for term_key in key.terms:
            term = by_name.get(term_key.name)
            if term is None:
                continue  # the uber-shader's terms this material does not have: the caller fills zeros
            unlit = {term_key.ambient_param if term_key.ambient else None, term_key.emission, term_key.occlusion}
            generated = {term.emission, term.occluded_by} - unlit  # read by material_emission only, where the key has them
            params = [p for p in term.active_params() if p.name not in generated] if term_key.lit else \
                [p for p in term.params if p.name in unlit]
            surface = term.surface_inputs()
            for p in params:
                if p.name in surface:  # scale * texture * vertex colour, per fragment (material_inputs)
                    values[term.uniform_name(f"{p.name}_scale")] = _validate.float32_uniform(surface[p.name].scale)
                    if surface[p.name].texture is not None:
                        values[term.uniform_name(f"{p.name}_texture")] = surface[p.name].texture
                else:
                    values[term.uniform_name(p.name)] = _validate.float32_uniform(term.uniform_value(p.name))
            if term_key.lit:  # tables as `TableData`: the renderer binds their textures, the twin reads them
                values.update({term.uniform_name(t.name): getattr(term, t.name) for t in term.tables})
        return values

    def surface_uniform_values(self, key):
        """The uniforms of the material's normal map and alpha mask that program ``key`` reads (radiance and
        G-buffer programs alike): ``u_normal_map_texture``, ``u_normal_map_scale``, ``u_alpha_mask_cutoff``,
        ``u_alpha_mask_scale`` and ``u_alpha_mask_texture``; ``u_alpha_blend`` and ``u_alpha_blend_texture`` in the
        programs that draw a blended layer (`glphong.gpu.peeling`)."""
        values = {}
        if key.normal_map:
            values["u_normal_map_texture"] = self.normal_map.texture
            values["u_normal_map_scale"] = _validate.float32_uniform(self.normal_map.scale)
        if key.alpha_blend in (1, 3):  # a blended layer: its alpha, constant (1) or textured (3)
            blend = self.alpha_blend
            values["u_alpha_blend"] = _validate.float32_uniform(blend.alpha.scale if blend.textured else blend.alpha)
            if blend.textured:
                values["u_alpha_blend_texture"] = blend.alpha.texture
        if key.alpha_mask:
            mask = self.alpha_mask
            values["u_alpha_mask_cutoff"] = _validate.float32_uniform(mask.cutoff)
            values["u_alpha_mask_scale"] = _validate.float32_uniform(mask.alpha.scale if mask.textured else mask.alpha)
            if mask.textured:
                values["u_alpha_mask_texture"] = mask.alpha.texture
        return values

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable: make a new material instead of setting {name!r}")

    def __eq__(self, other):
        return type(other) is type(self) and other.parameter_values() == self.parameter_values()

    def __hash__(self):
        return hash((type(self), tuple(self.parameter_values().items())))

    def __repr__(self):
        values = self.parameter_values()
        arguments = type(self).arguments() if hasattr(type(self), "arguments") else ()
        hidden = {a.name for a in arguments if not isinstance(a, Param) and values.get(a.name) == a.default}
        shown = [f"{k}={_short(v)}" for k, v in values.items() if k not in MATERIAL_KEYWORDS and k not in hidden]
        if any(values["ka"]):
            shown.append(f"ka={_short(values['ka'])}")
        if not values["two_sided"]:
            shown.append("two_sided=False")
        shown += [f"{k}={values[k]!r}" for k in ("normal_map", "alpha_mask", "alpha_blend") if values[k] is not None]
        return f"{type(self).__name__}({', '.join(shown)})"


def constant_part(value):
    """A parameter's value, or a surface input's constant ``scale``."""
    return getattr(value, "scale", value)


def surface_define(model, param):
    """``<MODEL>_<PARAM>_INPUT``: defined where a program sets the parameter per fragment."""
    return f"{model.upper()}_{param.upper()}_INPUT"


def _short(value):
    if value is None or isinstance(value, str) or not isinstance(value, (tuple, float, int)):
        return repr(value)
    if isinstance(value, tuple) and len(set(value)) == 1:
        return f"{value[0]:g}"
    return f"({', '.join(f'{c:g}' for c in value)})" if isinstance(value, tuple) else f"{value:g}"


def bind_arguments(cls, params, args, kwargs):
    """Map positional and keyword arguments onto ``params`` (validated values by name).

    ``params`` are the constructor's arguments in positional order: `Table`, `Param`, `Choice` and a
    `FresnelSlot` (whose default may be None, a valid value)."""
    if len(args) > len(params):
        raise TypeError(f"{cls.__name__}() takes at most {len(params)} positional arguments "
                        f"({', '.join(p.name for p in params)}) (got {len(args)})")
    names = [p.name for p in params]
    given = dict(zip(names, args))
    for name, value in kwargs.items():
        if name not in names:
            raise TypeError(f"{cls.__name__}() got an unexpected parameter {name!r} "
                            f"(parameters: {', '.join(names + list(getattr(cls, 'keywords', MATERIAL_KEYWORDS)))})")
        if name in given:
            raise TypeError(f"{cls.__name__}() got parameter {name!r} twice")
        given[name] = value
    out = {}
    for p in params:
        if p.name in given:
            out[p.name] = p.validate(given[p.name])
        elif p.default is not None or getattr(p, "optional", False) or not isinstance(p, (Param, Table)):
            out[p.name] = p.default
        else:
            raise TypeError(f"{cls.__name__}() missing parameter {p.name!r} ({p.kind} in {p.interval}"
                            f"{', ' + p.unit if p.unit else ''})")
    return out
