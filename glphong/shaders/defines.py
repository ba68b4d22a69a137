"""The ``#define`` lines of a program, generated from its `glphong.shaders.keys.ProgramKey` (docs/design.md
section 5): the outputs, the attributes read, the formulation and numerics pieces, the light kinds' array sizes and
structural defines, the terms' structural defines and surface-input modes."""
from glphong.definitions.material import surface_define
from glphong.shaders.options import INPUT_MODES, NUMERICS_DEFINES, TEXTBOOK_PIECES

__all__ = ["program_defines"]


def _plane_defines(key):
    """Which G-buffer planes the fragment stage writes, and where: a G-buffer program position at 0, normal at 1 and
    its extra planes packed after them in `GBUFFER_PLANES` order; a radiance program writing the frame passes' planes
    (``key.pass_planes``) each at its place from 1, the radiance at 0 (multiple render targets)."""
    if key.output == "gbuffer":
        where = {"position": 0, "normal": 1} | {name: 2 + i for i, name in enumerate(key.gbuffer_planes())}
    else:
        where = {name: 1 + i for i, name in enumerate(key.pass_planes)}
    out = [("WRITES_PLANES", "1" if where else "0")]
    out += [(f"PLANE_{name.upper()}", "1" if name in where else "0") for name in ("normal", "object", "uv")]
    return out + [(f"PLANE_{name.upper()}_LOCATION", str(i)) for name, i in where.items()]


def program_defines(key):
    """The generated ``#define`` lines of ``key`` (a `ProgramKey`) as (name, value) pairs, in the order the
    program's source lists them."""
    b = lambda flag: "1" if flag else "0"  # noqa: E731
    out = [
        ("OUTPUT_GBUFFER", b(key.output == "gbuffer")),
        ("OUTPUT_DISPLAY", b(key.output == "display")),
        ("HAS_NORMAL", b(key.has_normal)),
        ("HAS_TANGENT", b(key.has_tangent)),
        ("HAS_UV", b(key.has_uv)),
        ("HAS_COLOR", b(key.has_color)),
        ("HAS_INPUTS", b(bool(key.inputs))),
        ("HAS_LOD", b(key.has_lod)),
        ("HAS_FACE", b(key.has_face)),
        ("HAS_OBJECT", b(key.has_object)),
        ("HAS_UNPERTURBED", b(key.has_unperturbed)),
        ("NORMAL_MAP", b(key.normal_map)),
        ("ALPHA_MASK", str(key.alpha_mask)),
        *((("ALPHA_BLEND", str(key.alpha_blend)),) if key.alpha_blend else ()),  # only in a blended layer's programs
        *((f"{name.upper()}_LOCATION", str(where)) for name, where in
          ({"tangent": 2, "uv": 3, "color": 5} | dict(key.attribute_locations)).items()),
        ("NUM_LOD_TEXTURES", str(key.lod_textures)),
        ("TWO_SIDED", b(key.two_sided)),
        ("RUNTIME_SWITCHES", b(key.uber)),
        ("SHADE_PER_VERTEX", b(key.shade_per_vertex)),
        ("NAIVE", b(key.formulation == "naive")),
        *((define, b(piece in key.numerics or (key.formulation == "naive" and piece in TEXTBOOK_PIECES)))
          for piece, define in NUMERICS_DEFINES.items()),
        # SWITCH(u_flag): a float uniform flag in the uber-shader, the constant true otherwise
        ("SWITCH(flag)", "((flag) > 0.5)" if key.uber else "true"),
    ]
    if key.output == "shadow":
        out.append(("SHADOW_ORTHO", b(key.shadow_pass == "ortho")))
    if key.output not in ("shadow", "matte"):
        out += _plane_defines(key)
    if key.output not in ("gbuffer", "shadow", "matte"):
        out.append(("NEEDS_VIEW", b(key.needs_view)))
        if key.shadow_slots:
            out += [("SHADOW_MAP_SIZE", str(key.shadow_size)), ("SHADOW_FILTER_RADIUS", str(key.shadow_filter))]
        out.append(("NUM_LIGHTS", str(key.num_lights)))
        for light in key.lights:  # array sizes, loop bounds and each kind's structural defines, prefixed
            upper = light.name.upper()
            out.append((f"NUM_{upper}_LIGHTS", str(light.count)))
            out.append((f"{upper}_LIGHT_COUNT", f"int(u_{light.name}_count)" if key.uber else str(light.count)))
            out += [(f"{upper}_{name}", value) for name, value in light.defines]
        for term in key.terms:  # a model's structural defines, prefixed with its name
            out += [(f"{term.name.upper()}_{name}", value) for name, value in term.defines]
            out += [(surface_define(term.name, param), str(INPUT_MODES.index(mode.split(":")[0]) + 1))
                    for param, mode in term.inputs]
    return out

