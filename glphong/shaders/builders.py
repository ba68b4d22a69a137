"""The builders of program keys: a material's terms, a scene's light kinds, and the key of each kind of program
(a material in a scene, the G-buffer, the uber-shader, a material's response, a shadow pass) (docs/design.md
sections 5 and 8)."""
from dataclasses import replace

from glphong.definitions.light import light_for_key, registered_lights
from glphong.definitions.material import registered_models
from glphong.shaders.generated import terms_behind
from glphong.shaders.keys import LightKey, ProgramKey, TermKey
from glphong.shaders.options import MAX_TEXTURED_INPUTS, UBER_MAX_LIGHTS

__all__ = ["light_keys", "term_keys", "program_key", "gbuffer_key", "uber_key", "response_key", "shadow_key", "matte_key",
           "lod_slots"]


def light_keys(lights, casters=True):
    """The `LightKey` of each kind present in ``lights`` (a scene's light instances), in the registry's loop order;
    ``casters``: whether any object casts shadows (without, no light is shadowed)."""
    out = []
    for kind in registered_lights():
        mine = [light for light in lights if type(light) is kind]
        if mine:
            shadowed = tuple(j for j, light in enumerate(mine) if light.shadows) if casters else ()
            out.append(LightKey(kind.name, kind.source_hash(), len(mine), tuple(kind.structural_defines(mine)),
                                tuple(kind.uses), shadowed, kind.shadow_map, kind.key_integrals(mine), kind.occludable))
    return tuple(out)


def _as_light_keys(lights):
    """`light_keys` of light instances, or of a ``{kind name: count}`` dict (no structural defines), or the keys."""
    if isinstance(lights, dict):
        return tuple(LightKey(kind.name, kind.source_hash(), lights[kind.name], (), tuple(kind.uses),
                              integrals=kind.key_integrals(), occludable=kind.occludable)
                     for kind in registered_lights() if lights.get(kind.name, 0))
    lights = tuple(lights)
    if all(isinstance(light, LightKey) for light in lights):
        return lights
    return light_keys(lights)



def _ambient_present(ambient_radiance):
    return ambient_radiance is not None and any(c > 0.0 for c in ambient_radiance)


def _term_key(term, lit, ambient, uber=False, extended=False, emits=False, occludable=False):
    surface = term.surface_inputs()
    emission = term.emission if emits else None
    occlusion = term.occluded_by if ambient or (lit and occludable) else None
    read = ({p.name for p in term.params} - {term.emission, term.occluded_by} if lit else set()) \
        | {term.ambient if ambient else None, emission, occlusion}  # by the response, or by material_emission
    inputs = tuple((p.name, surface[p.name].mode) for p in term.params if p.name in surface and p.name in read)
    return TermKey(term.name, term.source_hash(), tuple(term.needs), lit=lit, ambient=ambient,
                   uses=term.library_uses(uber), defines=term.structural_defines(uber), ambient_param=term.ambient,
                   ambient_scale=float(term.ambient_scale), inputs=inputs,
                   integral=term.integral_form() if lit and extended else None, emission=emission, occlusion=occlusion)


def term_keys(material, lit, ambient_present, extended=False, emission=True, occludable=False):
    """The `TermKey` of each term of ``material`` that a program evaluates; ``extended``: the program has an
    extended light (each lit term's closed form, `TermKey.integral`, is part of the key); ``emission``: the program
    adds what the terms emit (not a response program); ``occludable``: it has a light its terms' occlusion darkens."""
    out = []
    for term in material.components:
        emits = emission and term.emits()
        if term.vanishes() and not emits:
            continue
        answers = ambient_present and term.answers_ambient() and not term.vanishes()
        reflects = lit and not term.vanishes()
        if reflects or answers or emits:
            out.append(_term_key(term, lit=reflects, ambient=answers, extended=extended, emits=emits,
                                 occludable=occludable))
    return tuple(out)


def response_key(material):
    """The key of a program that evaluates ``material``'s response at direction pairs (`glphong.testing`):
    every term that does not vanish, in the light loop's place, no light, no emission."""
    terms = tuple(t for t in term_keys(material, True, False, emission=False))
    _refuse_surface_inputs(terms, "glphong.testing evaluates a material's response at given directions, with "
                                  "constant parameters")
    needs = {n for t in terms for n in t.needs}
    return ProgramKey(output="response", terms=terms, has_normal=True, has_tangent="tangent" in needs,
                      has_uv="uv" in needs, two_sided=False)


def program_key(material, lights, ambient_radiance, output="radiance", gbuffer_needs=None):
    """The program key of one material in a scene.

    Parameters
    ----------
    material : glphong.materials.Material
    lights : sequence of LightModel, or tuple of LightKey, or dict of str to int
        The scene's lights (`light_keys` of them), their keys, or a number of lights per kind name
        (``{'point': 1}``: no structural defines).
    ambient_radiance : tuple of 3 float or None
        The scene's ``L_a``.
    output : {'radiance', 'gbuffer', 'points', 'display'}
    gbuffer_needs : set of str, optional
        For 'gbuffer': the extra outputs ('tangent', 'uv') the scene's G-buffer carries.

    Returns
    -------
    ProgramKey
    """
    if output == "gbuffer":
        spec = program_key(material, lights, ambient_radiance)
        values = material.uniform_values(spec) if spec.textured_inputs else {}
        _, shown = lod_slots([values[f"u_{t}_{p}_texture"] for t, p in spec.textured_inputs])
        if len(shown) > MAX_TEXTURED_INPUTS:
            raise ValueError(f"a material's textures may have at most {MAX_TEXTURED_INPUTS} sizes (the G-buffer holds "
                             f"one level of detail per size); {type(material).__name__} has {len(shown)}")
        return replace(gbuffer_key(material, gbuffer_needs or (), len(shown)), normal_map=spec.normal_map,
                       alpha_mask=spec.alpha_mask)
    # lights matter only to a material with a term that reflects them; a radiance program of KHR_materials_
    # transmission reads its terms' parameters and the normal with or without a light (glsl/transmission_thin.glsl)
    lights = _as_light_keys(lights)
    lit = (bool(lights) or (output == "radiance" and _sees_through(material))) and \
        any(not t.vanishes() for t in material.components)
    terms = term_keys(material, lit, _ambient_present(ambient_radiance), extended=any(k.extended for k in lights),
                      occludable=any(k.occludable for k in lights))
    behind = output == "radiance" and bool(terms_behind(terms))  # lights behind the surface: the kinds' samples
    lights = tuple(_with_usage(k, terms, behind) if k.extended else k for k in lights)
    needs = {n for t in terms if t.lit for n in t.needs}
    modes = [mode for t in terms for _, mode in t.inputs]
    normal_map = lit and material.normal_map is not None
    mask = material.alpha_mask
    alpha_mask = 0 if mask is None else 2 if mask.textured else 1
    if output == "points":
        _refuse_surface_inputs(terms, "shading at given points has no texture coordinates or vertex colours")
        if normal_map:
            raise ValueError("the material has a normal map, but shading at given points has no texture coordinates: "
                             "give the points their normals and a material without normal_map")
    return ProgramKey(
        output=output,
        terms=terms,
        has_ka=any(c > 0.0 for c in material.ka),
        lights=lights if lit else (),
        has_face=lit and any(k.shadowed for k in lights),
        has_normal=lit,
        has_tangent="tangent" in needs or normal_map,
        has_unperturbed=normal_map and "unperturbed" in needs,
        has_uv="uv" in needs or any("texture" in m for m in modes) or normal_map or alpha_mask == 2,
        two_sided=material.two_sided and lit,
        has_color=any("vertex" in m for m in modes),
        normal_map=normal_map,
        alpha_mask=alpha_mask,
    )


def _sees_through(material):
    """Whether ``material`` uses KHR_materials_transmission (a `GltfPBR`'s extensions)."""
    extensions = getattr(material, "extensions", None)
    return callable(extensions) and "transmission" in extensions()


def _with_usage(light, terms, behind=False):
    """An extended kind's `LightKey` with the defines its kind adds for what the program's lit ``terms`` use of it
    (`glphong.lights.LightModel.usage_defines`: its closed forms 'irradiance' and 'lobe', its samples 'sample');
    ``behind``: the program adds what the kind sends through the surface from behind, over its samples whatever the
    terms' closed forms (`glphong.shaders.generated`'s extended loop)."""
    lit = [t for t in terms if t.lit]
    closed = {t.integral.form for t in lit if t.integral is not None and t.integral.form in light.integrals}
    uses = tuple(sorted(closed)) + (("sample",) if behind or any(
        t.integral is None or t.integral.form not in light.integrals for t in lit) else ())
    extra = tuple(light_for_key(light.name, light.source_hash).usage_defines(light.defines, uses))
    return replace(light, defines=light.defines + extra) if extra else light


def _refuse_surface_inputs(terms, why):
    inputs = [f"{t.name}.{param}" for t in terms for param, _ in t.inputs]
    if inputs:
        raise ValueError(f"{', '.join(inputs)} vary over the surface (a texture or vertex colours), but {why}: "
                         "give the material constant parameters")


_UBER_BUILTINS = {}


def _uber_builtins():
    """Example instances of the models the uber-shader always holds (those that declare ``in_uber = True``:
    the lecture's Lambert, Phong and Blinn lobes; they need no more than the view and have no structural
    defines), computed once per state of the registry.  Every other model joins it only where a scene has it:
    each term costs every fragment its switch (benchmarks/specialisation.py, a Lambert sphere and floor at
    1024x1024 on EGL: 2.34x the specialised program with the lecture's three terms, 4.2x with the normalised
    lobes, the albedo diffuse term and the Fresnel switch compiled in too)."""

    models = registered_models()
    cached = _UBER_BUILTINS.get(models)
    if cached is None:
        examples = [m.example() for m in models if m.in_uber and set(m.needs) <= {"view"}]
        cached = _UBER_BUILTINS[models] = [e for e in examples if not e.structural_defines()]
    return cached


def uber_key(materials, output="radiance", formulation="stable", shade_per_vertex=False, lights=()):
    """The uber-shader's key: every built-in model that needs no more than the view vector, every
    term of ``materials``, and `UBER_MAX_LIGHTS` lights of each built-in kind (``in_uber``) and of each kind of
    ``lights``, with every optional part of their code, switched at run time by uniforms.

    Parameters
    ----------
    materials : sequence of glphong.materials.Material
        The materials drawn with it (a scene's); their terms are all compiled in.
    lights : sequence of LightModel
        The scene's lights: their kinds join the built-in ones.
    """
    extended = sorted({type(light).name for light in lights if type(light).extent == "extended"})
    if extended:
        raise ValueError(f"the uber-shader holds punctual lights only, but the scene has {', '.join(extended)} lights, "
                         "which integrate over a solid angle (docs/design.md section 13): render it with specialise=True")
    terms = {}
    drawn = [term for material in materials for term in material.components]
    textured = [f"{t.name}.{name}" for t in drawn for name in t.surface_inputs()]
    textured += [f"{type(m).__name__}'s normal map" for m in materials if m.normal_map is not None]
    textured += [f"{type(m).__name__}'s alpha mask" for m in materials if m.alpha_mask is not None]
    if textured:
        raise ValueError(f"the uber-shader holds constant parameters only, but {', '.join(textured)} vary over the "
                         "surface (a texture or vertex colours): render it with specialise=True")
    # a model's Fresnel form is a run-time switch, compiled only where one of the scene's terms has one
    # (computing F for every fragment and light would cost the lecture's models whatever the scene)
    with_fresnel = {t.name for t in drawn if getattr(t, "fresnel", None) is not None}
    for term in _uber_builtins() + drawn:
        key = _term_key(term, lit=True, ambient=term.ambient is not None, uber=term.name in with_fresnel,
                        emits=term.emission is not None)
        known = terms.setdefault(term.name, key)
        if known != key:
            raise ValueError(f"the uber-shader holds one variant of each model, but the scene has two of "
                             f"{term.name!r} (defines {known.defines} and {key.defines}, or two definitions): "
                             "render it with specialise=True")
    needs = {n for t in terms.values() for n in t.needs}
    kinds = {type(light).name for light in lights}
    uber_lights = tuple(LightKey(k.name, k.source_hash(), UBER_MAX_LIGHTS, tuple((name, "1") for name, _ in k.optional_code),
                                 tuple(k.uses)) for k in registered_lights() if k.in_uber or k.name in kinds)
    return ProgramKey(output=output, terms=tuple(terms[name] for name in sorted(terms)), has_ka=True,
                      lights=uber_lights, has_normal=True, has_tangent="tangent" in needs,
                      has_uv="uv" in needs, two_sided=True, formulation=formulation, uber=True,
                      shade_per_vertex=shade_per_vertex)


def shadow_key(shadow_pass):
    """The key of a shadow pass (a caster's distance from the light, glsl/shadow_fragment.glsl): 'cube' or 'ortho'."""
    return ProgramKey(output="shadow", has_normal=False, two_sided=False, shadow_pass=shadow_pass)


def matte_key():
    """The key of the matte pass (each sample's object index plus one, glsl/matte_fragment.glsl)."""
    return ProgramKey(output="matte", has_normal=False, two_sided=False)


def lod_slots(images):
    """Where the G-buffer keeps the level of detail of each of a program's textures: ``(slots, shown)``, ``slots[i]``
    the slot of ``images[i]`` (the `TextureImage` of ``ProgramKey.textured_inputs[i]``) and ``shown[k]`` the index of
    the image the G-buffer program samples for slot ``k``.  ``textureQueryLOD`` depends on the uv derivatives and the
    texture's size and number of levels only, so textures alike in those share a slot (glTF's textures mostly are:
    base colour, metallic-roughness, occlusion and emissive at one size take one slot)."""
    slots, shown, seen = [], [], {}
    for i, image in enumerate(images):
        shape = (image.size, len(image.levels))
        if shape not in seen:
            seen[shape] = len(shown)
            shown.append(i)
        slots.append(seen[shape])
    return tuple(slots), tuple(shown)


def gbuffer_key(material, needs=(), lod_textures=0):
    """The G-buffer-program key of one material: its two-sided flag, the scene's extra G-buffer outputs
    ``needs`` ('tangent', 'uv', 'color', 'lod', 'face', 'object', 'unperturbed') and the number of its textures whose
    level of detail it writes."""
    return ProgramKey(output="gbuffer", has_normal=True, two_sided=material.two_sided,
                      has_tangent="tangent" in needs, has_uv="uv" in needs, has_color="color" in needs,
                      has_lod="lod" in needs, lod_textures=lod_textures, has_face="face" in needs,
                      has_object="object" in needs, has_unperturbed="unperturbed" in needs)
