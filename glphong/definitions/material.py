"""The material mechanism: the lecture's Material class as an open definition (docs/design.md section 8).

One reflectance model is one `MaterialModel` subclass: its parameters (`Param`), what it needs
(the view vector, a tangent frame, UVs), its GLSL response ``<name>_response(f, wi, wo, n_dot_l)``
and its numpy twin ``response(f, wi, wo, n_dot_l, p)``, both returning

    f_r(wi, wo) (n.wi)    [1/sr], used only where n.wi > 0 (the shader may compute it elsewhere and
                          discard it by a select: any value, NaN included, is harmless there).

The radiance one light adds is ``response * E``.  A definition also states its answer to the
ambient light ``L_a`` (``ambient``: the rgb parameter ``k`` of a ``k L_a`` term), which parameter
values make it vanish (``vanishes_with``), its declared `Properties`, an error band against the
twin (`MaterialModel.band`; a generic default) and its extreme cases for the stability suite.

A material is a sum of terms: a `MaterialModel` instance is a material of one term, a
`MaterialSum` subclass names several (``terms = (Lambert, PhongLobe)``).  Every material takes
the keywords ``ka`` (a constant radiance ``k_a`` [W/(m^2 sr)]), ``two_sided``, ``normal_map`` and ``alpha_mask``.  The built-in
models use exactly this mechanism; a definition is checked when its class is created, so a
missing twin, a GLSL function of the wrong name or signature, a parameter without a range or a
name that clashes fails there, with a message saying what is wrong.
"""
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.definitions.material_base import Material, bind_arguments, constant_part, surface_define  # noqa: F401
from glphong.definitions.material_checks import check_definition
from glphong.definitions.params import (Choice, GlslFile, MaterialDefinitionError, Param, ParamValues, Properties,
                                        ShadingFrame)
from glphong.definitions.definition import Definition
from glphong.definitions.registry import MATERIALS, model_named, registered_models
from glphong.definitions.table import Table, TableData
from glphong.definitions.cases import generic_cases
from glphong.definitions.fresnel import FRESNEL_PARAMS, fresnel_uniform_values
from glphong.definitions.surface import SurfaceInput
from glphong.twin.band import EPS
from glphong.twin.functions import perpendiculars

__all__ = ["Integral", "bind_arguments", "surface_define", "constant_part", "Param", "Choice", "Table", "TableData", "Properties", "ParamValues", "ShadingFrame", "Material", "MaterialModel", "MaterialSum",
           "MaterialDefinitionError", "GlslFile", "registered_models", "model_named"]


@dataclass(frozen=True)
class Integral:
    """How a term's response integrates in closed form against an extended light (docs/design.md section 13).

    Attributes
    ----------
    form : {'irradiance', 'lobe', 'lobe_real'}
        'irradiance': the response is ``factor k (n.l)`` and the term reflects ``factor k E(n)``, the light's
        irradiance; 'lobe': the response is ``factor k max(r_v . l, 0)^q`` (``r_v`` the view reflected about
        ``n``) with an integer ``q`` and the term reflects ``factor k integral max(r_v . w, 0)^q L(w) [n.w > 0] dw``;
        'lobe_real': the same for a ``q`` that is not (a kind lists the forms it integrates in its ``integrals``).
    scale : str
        The rgb parameter ``k`` (its uniform ``u_<model>_<scale>``, a surface input where textured).
    factor : float
        A constant factor (``1/pi`` for an albedo).
    exponent : str or None
        The scalar parameter ``q`` of a lobe.
    """

    form: str
    scale: str
    factor: float = 1.0
    exponent: str = None


class MaterialModel(Material, Definition):
    """One reflectance model (a term of a material), defined the way the built-ins are (the definition mechanism of
    `glphong.definitions.definition.Definition`, which light kinds share).

    Class attributes a definition sets
    ----------------------------------
    name : str
        Lowercase GLSL prefix, unique: the GLSL defines ``<name>_response`` and reads uniforms
        ``u_<name>_<param>``; part of the program key.
    params : tuple of Param
    tables : tuple of Table
        Arrays the GLSL samples as textures (``sampler2D``/``sampler3D u_<name>_<table>``, declared by
        glphong); the twin reads the same float32 values (``p.<table>.array``).  Uploaded only when
        a drawn object's program reads them, once per content per context.
    needs : tuple of str
        Any of ``'view'`` (``wo`` is computed), ``'tangent'`` (``f.t``, ``f.b``), ``'uv'`` (``f.uv``).
        Nothing else is computed or uploaded.
    glsl : str or GlslFile
        GLSL source text, or the path of a ``.glsl`` file (relative to the module defining the
        class).  It defines ``vec3 <name>_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)``.
        The common chunk (``safe_normalize``, ``ShadingFrame``, ``FLT_MAX``) is always available.
    uses : tuple of str
        Library chunks the GLSL calls: ``'lobe'`` (``log_one_minus``, ``lobe_from_delta``, the Phong and
        Blinn lobes), ``'fresnel'`` (``fresnel_schlick``, ``fresnel_dielectric``), ``'angle'``
        (``atan2_first_quadrant``), ``'microfacet'`` (``microfacet_geometry``).
    ambient : str or None
        The rgb parameter ``k`` of the model's answer ``k L_a`` to the ambient light, or None.
    emission : str or None
        The rgb parameter the term emits as radiance [W/(m^2 sr)] (glTF's emissive), added to every fragment
        whatever the lights, or None.  Read by generated code only (``material_emission``).
    occluded_by : str or None
        The scalar parameter in [0, 1] (glTF's occlusion) that multiplies the term's answer to the ambient light and
        its reflection of the lights whose kind is `occludable` (the environment), not of punctual or area lights;
        or None.  Read by generated code only.
    vanishes_with : tuple of str
        Parameters that scale the whole term: where any of them is zero in every channel the term
        is left out of the program.
    properties : Properties
    choices : tuple of Choice
        Structural options (``form=``): each a ``#define <MODEL>_<NAME> <index>`` of the program.
    fresnel_slot : FresnelSlot or None
        Declares the ``fresnel=`` argument; the GLSL calls the generated ``<name>_fresnel(c)``.
    ambient_scale : float
        The answer to ``L_a`` is ``ambient_scale * <ambient param> * L_a`` (``1/pi`` for an albedo).
    in_uber : bool
        Compiled into every uber-shader, whether or not a scene has it (the lecture's models only;
        default False: a model joins the uber-shader of the scenes that draw it).
    lobe_exponent : str or None
        The parameter that is the exponent ``q`` of every ``lobe_from_delta(delta, q)`` the GLSL evaluates, for a
        model that calls lobe.glsl: ``Renderer(numerics='auto')`` leaves out the lobes' log branch where it is at
        least 151 (`glphong.shaders.numerics`).  None (default): a model that uses lobe.glsl keeps the branch.
    behind_responses : tuple of (str, str, str)
        ``(define, function, variable)`` of each GLSL response the model offers to a punctual light behind the surface
        (``n.wi < 0``): where its term carries the structural ``define`` (``#define <MODEL>_<define> 1``), the light
        loops add ``light_term(function(f, wi, wo, -n.wi), E)`` as ``variable`` (`glphong.shaders.generated`).  Empty
        (default): a light behind the surface sends nothing.
    behind_exits : tuple of (str, str, str or None, str)
        ``(define, variable, exit, attenuation)``: where the term carries ``define``, the behind response stored as
        ``variable`` takes the light seen from ``position + exit(f, wo)`` (the kind's incident there, gated on its own
        ``n.wi' < 0``; ``exit`` None: at ``position``), times ``attenuation(f, wo)`` (GLSL functions of the model's,
        each evaluated once per fragment; `GltfPBR`'s: KHR_materials_volume).  Empty (default): none.

    Methods a definition provides
    -----------------------------
    response(self, f, wi, wo, n_dot_l, p)
        The numpy twin: same name, argument order and formulation as the GLSL; ``f`` a
        `ShadingFrame`, ``wi``/``wo`` ``(N, 3)`` unit vectors, ``n_dot_l`` ``(N,)`` (> 0), ``p`` the
        `ParamValues`; returns ``(N, 3)``.
    band(self, f, wi, wo, n_dot_l, p, constants)  (optional)
        Interval of float32 GPU responses consistent with the float64 twin; the default widens
        the twin by its sensitivity to a few ulps of its inputs (see `MaterialModel.band`).
    oracle(self, f, wi, wo, n_dot_l, p)  (optional)
        The response in mpmath at high precision, for the stability suite (default: the twin): the
        same arguments as lists of mpmath numbers (``f.n``, ``f.t``, ``f.b``, ``f.uv``; ``p`` from the
        constructor's values rounded to float32), returning a list of 3.
    stability_cases(cls)  (optional classmethod)
        The model's extreme cases (default: grazing, behind and opposite geometry at example values).
    integral_form(self)  (optional)
        How the term reflects an extended light in closed form (an `Integral`), or None (default): the light's
        weighted directions are then summed with ``response`` (docs/design.md section 13).
    """

    params = ()
    tables = ()
    needs = ()
    glsl = None
    uses = ()
    ambient = None
    emission = None
    occluded_by = None
    vanishes_with = ()
    properties = Properties()
    choices = ()
    fresnel_slot = None
    ambient_scale = 1.0
    in_uber = False
    lobe_exponent = None
    behind_responses = ()
    behind_exits = ()

    registry = MATERIALS
    definition_error = MaterialDefinitionError
    definition_kind = "material"

    @classmethod
    def check_unnamed(cls):
        """A subclass without a name of its own is abstract or pure Python: it may not redefine the GLSL, twin or
        parameters, which would render as its parent."""
        own = cls.__dict__
        redefined = [a for a in ("glsl", "response", "params", "tables", "needs", "uses") if a in own]
        if redefined and cls.name is not None:
            raise MaterialDefinitionError(
                f"{cls.__qualname__} redefines {', '.join(redefined)} but keeps the name {cls.name!r} of "
                f"{cls.__mro__[1].__qualname__}: give it a name of its own (name = '...'), or it would "
                "render as its parent")
        if cls.name is None and ("glsl" in own or "response" in own):
            raise MaterialDefinitionError(f"{cls.__qualname__} defines a model but no name: add name = '...' "
                                          "(a lowercase GLSL prefix)")

    @classmethod
    def check_definition(cls):
        """The checks of `glphong.definitions.material_checks` (raising `MaterialDefinitionError`)."""
        check_definition(cls, MaterialModel)

    def integral_form(self):
        """How this term reflects an extended light in closed form (`Integral`), or None: sampled (default)."""
        return None

    def __init__(self, *args, ka=0.0, two_sided=True, normal_map=None, alpha_mask=None, alpha_blend=None, **kwargs):
        if type(self).name is None:
            raise TypeError(f"{type(self).__name__} is not a material model (it has no name)")
        for name, value in bind_arguments(type(self), self.arguments(), args, kwargs).items():
            object.__setattr__(self, name, value)
        self._set_common(ka, two_sided, normal_map, alpha_mask, alpha_blend)

    @classmethod
    def arguments(cls):
        """The constructor's arguments in positional order: `tables`, `params`, then ``fresnel`` (where the
        model has a `fresnel_slot`), then `choices` (tuple)."""
        return cls.tables + cls.params + ((cls.fresnel_slot,) if cls.fresnel_slot is not None else ()) + cls.choices

    @classmethod
    def uniform_params(cls):
        """Every uniform the model's chunk declares, as `Param`: `params`, and ``fresnel_f0`` and
        ``fresnel_ior`` where the model has a `fresnel_slot` (tuple)."""
        if cls.fresnel_slot is None:
            return cls.params

        return cls.params + FRESNEL_PARAMS

    def active_params(self):
        """The uniforms this instance's programs read: `uniform_params` less the Fresnel factor's where
        it has none (tuple of Param)."""
        return self.params if getattr(self, "fresnel", None) is None else self.uniform_params()

    def uniform_value(self, name):
        """The value of the uniform ``u_<model>_<name>`` (a param, or the Fresnel factor's: no param may
        start with ``fresnel_``)."""
        if self.fresnel_slot is not None and name.startswith("fresnel_"):
            return fresnel_uniform_values(self.fresnel)[name]
        return getattr(self, name)

    def structural_defines(self, uber=False):
        """Every ``(NAME, value)`` define of this instance (un-prefixed): its `choices`' indices, its
        Fresnel form (``FRESNEL_SCHLICK`` or ``FRESNEL_DIELECTRIC``, none for ``fresnel=None``;
        ``FRESNEL_RUNTIME`` in the ``uber``-shader, whatever the instance's) and `defines`.  The key
        emits each as ``<MODEL>_<NAME>``."""
        out = [c.define(getattr(self, c.name)) for c in self.choices]
        if self.fresnel_slot is not None and uber:
            out.append(("FRESNEL_RUNTIME", "1"))
        elif self.fresnel_slot is not None and self.fresnel is not None:
            out.append((f"FRESNEL_{self.fresnel.form.upper()}", "1"))
        return tuple(out) + tuple(self.defines())

    def library_uses(self, uber=False):
        """Library chunks this instance's program needs: `uses`, and ``'fresnel'`` where it has a
        Fresnel factor, or a slot in the ``uber``-shader (tuple)."""
        extra = ("fresnel",) if self.fresnel_slot is not None and (self.fresnel is not None or uber) else ()
        return tuple(dict.fromkeys(tuple(self.uses) + extra))

    @property
    def components(self):
        return (self,)

    # ---- what the program key and the uniforms are made of (uniform_name, source, source_hash: `Definition`)
    @classmethod
    def uniform_guard(cls, name):
        """The define under which a program declares the uniform of parameter ``name``, or None (the default:
        every program of the model declares it).  A model whose GLSL reads a parameter only under one of its
        structural defines (`defines`, prefixed ``<MODEL>_``) may name that define."""
        return None

    @classmethod
    def uniform_declarations(cls):
        """The GLSL declarations of the model's uniforms, generated from `params` and `tables`; where the
        model has a `fresnel_slot`, also its Fresnel uniforms and ``vec3 <name>_fresnel(float c)``."""
        lines = []
        for p in cls.uniform_params():
            line = f"{p.glsl_type} {cls.uniform_name(p.name)};  // {p.kind} in {p.interval}{' [' + p.unit + ']' if p.unit else ''}"
            if p.textureable:  # a surface input: a global set per fragment by material_inputs() (key.py)
                entry = [f"#if defined({surface_define(cls.name, p.name)})", f"{line}, per fragment: material_inputs()",
                         "#else", f"uniform {line}", "#endif"]
            else:
                entry = [f"uniform {line}"]
            guard = cls.uniform_guard(p.name)
            lines += [f"#if defined({guard})", *entry, "#endif"] if guard else entry
        lines += [f"uniform {t.glsl_type} {cls.uniform_name(t.name)};  // table {t.shape} x {t.channels}"
                  f"{' [' + t.unit + ']' if t.unit else ''}" for t in cls.tables]
        if cls.fresnel_slot is not None:
            upper, name = cls.name.upper(), cls.name
            lines += [f"// the Fresnel factor F(c) of fresnel= (glphong/definitions/fresnel.py), c = {cls.fresnel_slot.cosine}",
                      f"vec3 {name}_fresnel(float c)", "{",
                      f"#if defined({upper}_FRESNEL_SCHLICK)",
                      f"    return fresnel_schlick(u_{name}_fresnel_f0, c);",
                      f"#elif defined({upper}_FRESNEL_DIELECTRIC)",
                      f"    return vec3(fresnel_dielectric(u_{name}_fresnel_ior, c));",
                      f"#elif defined({upper}_FRESNEL_RUNTIME)  // the uber-shader: the form is a uniform, so",
                      "    // the branches are uniform too: llvmpipe skips a branch no fragment takes",
                      f"    if (u_{name}_fresnel_form == 1.0) return fresnel_schlick(u_{name}_fresnel_f0, c);",
                      f"    if (u_{name}_fresnel_form == 2.0) return vec3(fresnel_dielectric(u_{name}_fresnel_ior, c));",
                      "    return vec3(1.0);",
                      "#else", "    return vec3(1.0);", "#endif", "}"]
        return "\n".join(lines)

    def defines(self):
        """Structural ``#define`` pairs ``(NAME, value)`` of this instance (part of its key; default none).

        For what changes the program's shape rather than a uniform's value (a number of lobes, a
        form).  Each is emitted as ``#define <MODEL>_<NAME> value`` (the model's name upper-cased),
        so models cannot collide; the model's GLSL reads it under that name.
        """
        return ()

    def vanishes(self):
        """True where a `vanishes_with` parameter is zero in every channel (a surface input: its scale):
        the term is left out."""
        return any(not np.any(constant_part(getattr(self, name))) for name in self.vanishes_with)

    def answers_ambient(self):
        """True where the model answers ``L_a`` with a non-zero ``k``."""
        return self.ambient is not None and bool(np.any(constant_part(getattr(self, self.ambient))))

    def emits(self):
        """True where the model declares an `emission` parameter and it is not zero in every channel."""
        return self.emission is not None and bool(np.any(constant_part(getattr(self, self.emission))))

    def gltf_fields(self, texture_index):
        """glTF's own material fields for this term, where the model is a glTF material (`GltfPBR`); None otherwise,
        and `glphong.save_gltf` writes an approximation (its base colour) for other viewers.

        Parameters
        ----------
        texture_index : callable
            ``texture_index(TextureImage) -> int``: the file's texture index of an image (written once).

        Returns
        -------
        (dict, dict) or None
            The ``pbrMetallicRoughness`` fields, and the material's other fields (``emissiveFactor``, extensions).
        """
        return None

    def surface_inputs(self):
        """The parameters given a `SurfaceInput` (a texture or vertex colours), by name (dict)."""

        return {p.name: getattr(self, p.name) for p in self.params if isinstance(getattr(self, p.name), SurfaceInput)}

    def values_from_uniforms(self, uniforms, dtype=np.float64, names=None, inputs=None):
        """`ParamValues` from a program's uniforms (the float32 values the GPU was given), with this
        instance's structure: its choices (by value) and ``fresnel_form`` (0 none, 1 Schlick, 2 dielectric).

        ``names`` limits them (an ambient-only term has only its ambient parameter).  ``inputs`` maps
        the uniform name of each surface input to its per-fragment values, (N, 3) (the twin's
        `glphong.reference.material_inputs`); those parameters are (N, 3) arrays.  The `emission` and `occluded_by`
        parameters, which only generated code reads, are left out where the program has neither."""
        given = set(uniforms) | set(inputs or ())
        params = [p for p in self.uniform_params() if (names is None or p.name in names) and not
                  (p.name in (self.emission, self.occluded_by) and self.uniform_name(p.name) not in given)]
        surface = self.surface_inputs()
        if surface and inputs is None:
            raise ValueError(f"{type(self).__name__}: {', '.join(surface)} vary over the surface (a texture or vertex "
                             "colours): their values per fragment are needed (inputs=)")

        def value(p):
            name = self.uniform_name(p.name)
            if p.name in surface:
                return inputs[name]
            return uniforms[name] if p in self.active_params() else _validate.float32_uniform(self.uniform_value(p.name))

        values = {p.name: np.asarray(value(p), dtype=dtype) for p in params}
        values |= {t.name: uniforms[self.uniform_name(t.name)] for t in self.tables if names is None or t.name in names}
        return ParamValues(values | self.structure())

    def values(self, dtype=np.float64):
        """`ParamValues` of this instance: its values as the GPU receives them (float32, subnormals
        flushed), in ``dtype``, with its structure as in `values_from_uniforms`.  An instance with a
        surface input has no single value: ValueError."""
        if self.surface_inputs():
            raise ValueError(f"{type(self).__name__}: {', '.join(self.surface_inputs())} vary over the surface (a texture "
                             "or vertex colours); this evaluates constant parameters: pass constants")
        return ParamValues({p.name: np.asarray(_validate.float32_uniform(self.uniform_value(p.name)), dtype=dtype)
                            for p in self.uniform_params()} | {t.name: getattr(self, t.name) for t in self.tables}
                           | self.structure())

    def structure(self):
        """What the twin reads beside the uniforms (dict): each choice's value by name, and ``fresnel_form``
        (0 none, 1 Schlick, 2 dielectric) where the model has a Fresnel slot."""
        out = {c.name: getattr(self, c.name) for c in self.choices}
        if self.fresnel_slot is not None:
            out["fresnel_form"] = 0 if self.fresnel is None else self.fresnel.index
        return out

    # ---- the twin and what is built on it
    def response(self, f, wi, wo, n_dot_l, p):
        """The numpy twin of ``<name>_response``: ``f_r (n.wi)`` [1/sr], (N, 3)."""
        raise NotImplementedError

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """Interval ``(low, high)``, each (N, 3), of float32 GPU responses consistent with the twin.

        The generic default, for models that do not derive their own: the twin's first-order
        sensitivity to its inputs, each perturbed by a few ulps as float32 arithmetic perturbs
        them: ``wi`` and ``wo`` rotated by ``D eps`` about two axes each and scaled by
        ``1 +- D eps`` (so every dot product the model forms with them moves by about ``D eps``,
        also at normal incidence), the frame's ``n``, ``t`` and ``b`` scaled likewise, ``n_dot_l``
        moved by ``+-D eps``, every scalar parameter scaled by ``1 +- A eps`` (which also stands
        for the error of a ``pow`` or ``exp`` it feeds); the deviations add up worst-case, and the
        result is widened by ``eps (A + B |ln r|)`` relative (``exp``/``pow`` error).

        ``n_dot_l`` may be as low as ``-D eps`` where the light gate is uncertain (the caller then
        accepts 0 as well); a band must bound the response over ``(0, n.l + D eps]``.  The default
        evaluates the twin at ``max(n.l, tiny)`` there.
        """

        tiny = np.finfo(np.float64).tiny
        n_dot_l = np.maximum(n_dot_l, tiny)
        base = np.asarray(self.response(f, wi, wo, n_dot_l, p), dtype=np.float64)
        up = np.zeros_like(base)
        down = np.zeros_like(base)

        def add(value):
            with np.errstate(invalid="ignore"):
                delta = np.nan_to_num(np.asarray(value, dtype=np.float64) - base, nan=0.0)
            np.maximum(up, delta, out=up)
            np.minimum(down, delta, out=down)

        angle = constants.D * EPS
        for which in ("wi", "wo"):
            vector = wi if which == "wi" else wo
            for axis in perpendiculars(vector):
                for sign in (1.0, -1.0):
                    turned = vector + sign * angle * axis
                    turned = turned / np.linalg.norm(turned, axis=-1, keepdims=True)
                    args = (turned, wo) if which == "wi" else (wi, turned)
                    with np.errstate(all="ignore"):
                        add(self.response(f, *args, n_dot_l, p))
            for sign in (1.0, -1.0):
                args = (vector * (1.0 + sign * angle), wo) if which == "wi" else (wi, vector * (1.0 + sign * angle))
                with np.errstate(all="ignore"):
                    add(self.response(f, *args, n_dot_l, p))
        for field in ("n", "t", "b"):
            if getattr(f, field) is None:
                continue
            for sign in (1.0, -1.0):
                scaled = ShadingFrame(**{**f.__dict__, field: getattr(f, field) * (1.0 + sign * angle)})
                with np.errstate(all="ignore"):
                    add(self.response(scaled, wi, wo, n_dot_l, p))
        for sign in (1.0, -1.0):
            moved = np.maximum(n_dot_l + sign * angle, tiny)
            with np.errstate(all="ignore"):
                add(self.response(f, wi, wo, moved, p))
        for param in self.uniform_params():
            if param.kind != "scalar" or param.name == "fresnel_form" or param.name not in p.__dict__:
                continue  # an index, not a measured value; or a parameter the response does not read
            for sign in (1.0, -1.0):
                scaled = ParamValues({**p.__dict__, param.name: p.__dict__[param.name] * (1.0 + sign * constants.A * EPS)})
                with np.errstate(all="ignore"):
                    add(self.response(f, wi, wo, n_dot_l, scaled))
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = np.abs(np.log(np.abs(base)))
        rel = EPS * (constants.A + constants.B * np.nan_to_num(lam, nan=0.0, posinf=0.0))
        # the worst-case sum of the deviations, widened around the base value; a non-finite twin
        # value is its own band (the GPU must match it)
        finite = np.isfinite(base)
        with np.errstate(invalid="ignore"):
            low = np.where(finite, base + down - np.abs(base) * rel, base)
            high = np.where(finite, base + up + np.abs(base) * rel, base)
        return low, high

    oracle = None

    @classmethod
    def example(cls, **overrides):
        """An instance at representative values (`Param.example`), with ``overrides``."""
        return cls(**{p.name: p.example() for p in cls.tables + cls.params} | overrides)

    @classmethod
    def stability_cases(cls):
        """The model's extreme cases for `glphong.checks.stability` (default: generic geometry, see there)."""

        return generic_cases(cls.name, cls.example())


class MaterialSum(Material):
    """A material made of several terms (a diffuse term plus lobes): ``terms = (Lambert, PhongLobe)``.

    Its parameters are its terms' parameters, in order (their names must differ); positional and
    keyword arguments map onto them, and each term is built with its own.  The radiance is the
    sum of the terms' contributions.  `properties` is derived from the terms (a property holds
    when every term declares it) unless the class declares its own.
    """

    terms = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        own = [a for a in ("glsl", "response", "params", "needs") if a in cls.__dict__]
        if own:
            raise MaterialDefinitionError(
                f"{cls.__qualname__} is a MaterialSum and defines {', '.join(own)}, which a sum does not use (it "
                "would render as the sum of its terms): define a MaterialModel with its own name for new GLSL, "
                "and list it in terms")
        terms = cls.terms
        if not isinstance(terms, tuple) or not terms or not all(
                isinstance(t, type) and issubclass(t, MaterialModel) and t.name for t in terms):
            raise MaterialDefinitionError(f"{cls.__qualname__}.terms must be a non-empty tuple of MaterialModel "
                                          "subclasses that have a name")
        models = [t.name for t in terms]
        if len(set(models)) != len(models):
            raise MaterialDefinitionError(f"{cls.__qualname__}.terms repeats a model ({models}): their uniforms would clash")
        names = [a.name for t in terms for a in t.arguments() if a.name != "fresnel"]
        if len(set(names)) != len(names):
            raise MaterialDefinitionError(f"{cls.__qualname__}: its terms' parameter names must differ (got {names})")
        if "properties" not in cls.__dict__:
            props = [t.properties for t in terms]
            both = lambda attr: (all(getattr(p, attr) for p in props) if all(  # noqa: E731
                getattr(p, attr) is not None for p in props) else None)
            cls.properties = Properties(reciprocal=both("reciprocal"), isotropic=both("isotropic"),
                                        non_negative=both("non_negative"))
        if cls.name is None:
            cls.name = cls.__name__.lower()

    @classmethod
    def all_params(cls):
        """The terms' parameters, in order (tuple of Param)."""
        return tuple(p for t in cls.terms for p in t.params)

    @classmethod
    def arguments(cls):
        """The constructor's arguments in positional order: the terms' params, then ``fresnel`` (passed
        to every term with a fresnel slot), then the terms' choices."""
        slots = [t.fresnel_slot for t in cls.terms if t.fresnel_slot is not None]
        return cls.all_params() + tuple(slots[:1]) + tuple(c for t in cls.terms for c in t.choices)

    def __init__(self, *args, ka=0.0, two_sided=True, normal_map=None, alpha_mask=None, alpha_blend=None, **kwargs):
        if not type(self).terms:
            raise TypeError(f"{type(self).__name__} has no terms")
        values = bind_arguments(type(self), self.arguments(), args, kwargs)
        parts = tuple(t(**{a.name: values[a.name] for a in t.arguments()}, two_sided=two_sided) for t in self.terms)
        object.__setattr__(self, "_parts", parts)
        self._set_common(ka, two_sided, normal_map, alpha_mask, alpha_blend)

    @property
    def components(self):
        return self._parts

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        for part in self.__dict__.get("_parts", ()):
            if name in {a.name for a in part.arguments()}:
                return getattr(part, name)
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")
