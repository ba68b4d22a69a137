"""What `glphong describe` says of a program: the one-line description of its key and the readable list of what
it leaves out (docs/design.md section 5)."""
from dataclasses import fields

from glphong.core.glsl_files import library_chunks
from glphong.definitions.light import registered_lights
from glphong.shaders.generated import model_chunk_label
from glphong.shaders.options import GBUFFER_PLANES, UBER_MAX_LIGHTS

__all__ = ["left_out", "describe_key"]


def left_out(key, absent_terms=()):
    """What the program of ``key`` (a `ProgramKey`) does not contain, one readable line per item (list of str).

    Parameters
    ----------
    absent_terms : sequence of (MaterialModel subclass, str)
        Terms of the drawn materials that the key leaves out, with the reason.
    """
    if key.output == "gbuffer":
        return ["all shading code and lights (the G-buffer program writes the shading inputs only)",
                "radiance output"] + [f"{name} output (no {'pass asks' if name == 'object' else 'drawn term needs'} it)"
                                      for name in GBUFFER_PLANES if name not in key.gbuffer_planes()]
    if key.output == "shadow":
        return ["all shading code (the shadow pass writes each caster's distance from the light)"]
    if key.output == "matte":
        return ["all shading code (the matte pass writes each sample's object)"]
    if key.uber:
        return ["nothing: the uber-shader compiles every built-in term and the scene's own and switches at run time"]
    out = []
    for model, reason in absent_terms:
        params = ", ".join(model.uniform_name(p.name) for p in model.params + model.tables)
        out.append(f"term {model.name}: {model_chunk_label(model.name)}{', ' + params if params else ''} ({reason})")
    used = set(key.library_chunks() + key.light_library_chunks())

    for chunk in library_chunks("light"):
        if chunk not in used:
            out.append(f"library chunk {chunk}.glsl (no term or light kind of this program calls it)")
    if not key.needs_view:
        out.append("view vector v = normalize(eye - x) and u_eye (no lit term reads it)")
    if not key.has_ka:
        out.append("constant term k_a (ka = 0)")
    if not key.has_ambient:
        out.append("ambient light L_a and u_ambient (no AmbientLight, or no term answers it)")
    present = {k.name: k for k in key.lights}
    for kind in registered_lights():
        if kind.name not in present:
            out.append(f"{kind.name}-light loop, its chunk {kind.source_label()} and uniform arrays "
                       f"(no {kind.name} light reaches this material)")
        else:
            given = {name for name, _ in present[kind.name].defines}
            out += [f"{kind.name} lights' {what} (no {kind.name} light of the scene needs it)"
                    for name, what in kind.optional_code if name not in given]
    if not key.shadow_slots:
        out.append("shadow maps, their samplers and shadows.glsl (no light has shadows=True, or nothing casts)")
    if not key.has_normal:
        out.append("normal attribute, its upload and the normal matrix (nothing reads a normal)")
    if not key.two_sided:
        out.append("two-sided normal flip")
    if not key.has_tangent:
        out.append("tangent attribute and the tangent frame (no lit term needs 'tangent')")
    if not key.has_uv:
        out.append("uv attribute (no lit term needs 'uv', no parameter is textured)")
    if not key.has_color:
        out.append("vertex-colour attribute (no parameter takes vertex colours)")
    if not key.textured_inputs:
        out.append("surface.glsl, texture samplers and material_inputs() (no parameter is textured)")
    if not key.normal_map:  # a coat normal (gltf_pbr) calls normal_map.glsl without a normal map
        held = "normal_map" in key.included_library()
        out.append(("the normal map sampler" if held else "normal_map.glsl and its sampler")
                   + " (the material has no normal map)")
    if not key.alpha_mask:
        out.append("the alpha test (the material has no alpha mask)")
    out.append("G-buffer outputs (they exist only in the G-buffer program)")
    return out


def describe_key(key):
    """One line naming every field of ``key`` (a `ProgramKey`) that is set, e.g. ``radiance terms=lambert[lit]+phong_lobe[lit] lights=point*2``."""
    if key.uber:
        return (f"{key.output} uber (terms {'+'.join(t.name for t in key.terms) or 'none'}, "
                f"{UBER_MAX_LIGHTS} lights of each of {'+'.join(k.name for k in key.lights)}, switched by uniforms)"
                f"{'' if key.formulation == 'stable' else ' formulation=' + key.formulation}")
    parts = [key.output]
    for f in fields(key):
        v = getattr(key, f.name)
        if f.name in ("terms", "lights"):
            if v:
                parts.append(f"{f.name}=" + "+".join(t.describe() for t in v))
        elif f.name != "output" and v not in (False, 0, None, "stable", ()):
            parts.append(f.name if v is True else f"{f.name}={v}")
    return " ".join(parts)


