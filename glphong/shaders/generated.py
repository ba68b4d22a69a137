"""The GLSL chunks generated from a program key: the material chunk that sums a material's terms
(`material_chunk`, label ``generated:material``), the loops over the program's light kinds (`lights_chunk`,
label ``generated:lights``) and a textured G-buffer program's levels of detail (`lod_chunk`, label
``generated:levels_of_detail``).  Generated text, never text substitution: the rest of a program is the
shipped chunk files.
"""
import numpy as np

from glphong.definitions.registry import model_named, model_source

__all__ = ["MATERIAL_CHUNK", "LIGHTS_CHUNK", "LOD_CHUNK", "material_chunk", "lights_chunk", "lod_chunk", "transmits",
           "terms_behind", "model_chunk_label"]

#: the label of the generated material chunk
MATERIAL_CHUNK = "generated:material"
#: the label of the generated chunk of light loops
LIGHTS_CHUNK = "generated:lights"
#: the label of the generated levels-of-detail chunk of a textured G-buffer program
LOD_CHUNK = "generated:levels_of_detail"


def model_chunk_label(name):
    """Where a model's GLSL comes from, for messages (its file, or its class)."""

    return model_source(model_named(name))[1]


def _switch(key, flag, statement):
    return f"    if (SWITCH({flag})) {statement}" if key.uber else f"    {statement}"


def _glsl_float(value):
    """A GLSL float literal that reads back as ``value`` rounded to float32 (a Python float's repr always
    has a '.' or an exponent)."""
    return repr(float(np.float32(value)))


def material_chunk(key):
    """The generated GLSL that sums the key's terms (label ``generated:material``).

    ``material_emission() = k_a + sum_terms (o_term k_term L_a + e_term)`` (``o`` a term's occlusion, 1 without;
    ``e`` what it emits, 0 without) and
    ``material_response(f, wi, wo, n_dot_l) = sum_lit_terms <model>_response(f, wi, wo, n_dot_l)``;
    in the uber-shader every term is behind a ``SWITCH(u_use_<model>)`` uniform flag.
    """
    lines = ["// material (generated from the program key) -- the material as a sum of its terms (docs/design.md section 8):",
             "//   material_emission() = k_a + sum_terms (o k L_a + e)                  [W/(m^2 sr)]",
             "//     (o a term's occlusion, e the radiance it emits, where it declares them)",
             "//   material_response(f, wi, wo, n_dot_l) = sum_terms <model>_response    [1/sr], times cos"]
    if key.uber:
        lines += ["uniform float u_use_ka;"] + [f"uniform float u_use_{t.name};" for t in key.lit_terms]
        lines += [f"uniform float u_use_{t.name}_ambient;" for t in key.terms if t.ambient]
        lines += [f"uniform float u_use_{t.name}_emission;" for t in key.terms if t.emission]
        lines += [f"uniform float u_{light.name}_count;" for light in key.lights]
    if key.has_ka:
        lines.append("uniform vec3 u_ka;                 // k_a [W/(m^2 sr)]")
    if key.has_ambient:
        lines.append("uniform vec3 u_ambient;            // L_a [W/m^2]")
    lines += ["", "vec3 material_emission()", "{", "    vec3 radiance = vec3(0.0);"]
    if key.has_ka:
        lines.append(_switch(key, "u_use_ka", "radiance += u_ka;"))
    for t in key.terms:
        if t.ambient:
            scaled = "u_ambient" if t.ambient_scale == 1.0 else f"({_glsl_float(t.ambient_scale)} * u_ambient)"
            answer = f"u_{t.name}_{t.ambient_param} * {scaled}"
            answer = f"u_{t.name}_{t.occlusion} * ({answer})" if t.occlusion else answer
            lines.append(_switch(key, f"u_use_{t.name}_ambient", f"radiance += {answer};"))
        if t.emission:
            lines.append(_switch(key, f"u_use_{t.name}_emission", f"radiance += u_{t.name}_{t.emission};"))
    lines += ["    return radiance;", "}", "",
              "vec3 material_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)", "{",
              "    vec3 response = vec3(0.0);"]
    for t in key.lit_terms:  # a term that does not need the view gets v = 0, whatever the others need
        view = "wo" if "view" in t.needs else "vec3(0.0)"
        lines.append(_switch(key, f"u_use_{t.name}", f"response += {t.name}_response(f, wi, {view}, n_dot_l);"))
    lines += ["    return response;", "}"]
    if key.inputs:
        lines += ["", "// surface inputs (glsl/surface.glsl): u_<model>_<param> = scale * texture(uv) * vertex colour",
                  "// (a scalar parameter: one channel c of each, scale * texture(uv).c * colour.c)"]
        for term, param, mode in key.inputs:
            lines.append(f"uniform {'vec3' if ':' not in mode else 'float'} u_{term}_{param}_scale;")
            if "texture" in mode:
                lines.append(f"uniform sampler2D u_{term}_{param}_texture;")
        lines += ["", "void material_inputs(vec2 uv, vec3 color)", "{"]
        for term, param, mode in key.inputs:
            channel = "." + mode.split(":")[1] if ":" in mode else ""
            factors = [f"u_{term}_{param}_scale"]
            factors += [f"surface_texture(u_{term}_{param}_texture, uv){channel}"] if "texture" in mode else []
            factors += [f"color{channel}"] if "vertex" in mode else []
            lines.append(f"    u_{term}_{param} = {' * '.join(factors)};")
        lines.append("}")
    return "\n".join(lines) + "\n"


def lights_chunk(key):
    """The generated GLSL of the key's light loops (label ``generated:lights``), one loop per kind present, in
    `ProgramKey.lights` order (docs/design.md section 11):

    ``add_lights(radiance, x, f, wo, lit)``: for each light j of kind k,
    ``valid = k_incident(x, j, wi, E)``;  ``radiance += (lit && valid && n.wi > 0) ? light_term(material_response(f,
    wi, wo, n.wi), E) : 0``.  Every light's term is computed and the gate selects it, without a branch (shade.glsl
    says why); the loop bound is the compile-time ``<KIND>_LIGHT_COUNT`` (a uniform in the uber-shader).  A program
    that `transmits` (KHR_materials_transmission) also adds, for a punctual light behind the surface,
    ``(lit && valid && n.wi < 0) ? light_term(gltf_transmission_response(f, wi, wo, -n.wi), E) : 0``
    (glsl/transmission_thin.glsl), and one with KHR_materials_diffuse_transmission
    ``(lit && valid && n.wi < 0) ? light_term(gltf_diffuse_transmission_response(f, wi, wo, -n.wi), E) : 0``
    (glsl/materials/gltf_pbr.glsl).  Where a response has an exit (`_behind_exits`: KHR_materials_volume, the glTF
    Sample Viewer's punctual loop), the light is seen from ``position + exit(f, wo)``: ``valid' =
    k_incident(position + exit, j, wi', E')`` (times the shadow's visibility at ``position``), ``(lit && valid' &&
    n.wi' < 0) ? light_term(response(f, wi', wo, -n.wi'), E') attenuation(f, wo) : 0``; one with an attenuation only
    (the diffuse transmission's) is multiplied by it.
    """
    lines = ["// light loops (generated from the program key): for each light j of each kind k present",
             "//   valid = k_incident(x, j, wi, E);  L += (lit && valid && n.wi > 0) ? material_response(f, wi, wo, n.wi) E : 0",
             "// a shadowed light's E is multiplied by its map's visibility V (glsl/shadows.glsl), its kind unrolled;",
             "// an extended kind (docs/design.md section 13): each term's closed form (k E(n), k_s lobe about r_v) where",
             "// the kind has it, the other terms over its weighted directions"]
    slots = {}
    for slot, (light, j) in enumerate(key.shadow_slots):
        slots[(light.name, j)] = slot
        lines.append(f"uniform sampler2D u_shadow_map{slot};   // {light.name} light {j}: {light.shadow_map} map")
        lines.append(f"uniform vec3 u_shadow_origin{slot};")
        lines.append(f"uniform float u_shadow_texel{slot};")
        if light.shadow_map == "ortho":
            lines += [f"uniform vec3 u_shadow_axis{slot};", f"uniform vec3 u_shadow_e1{slot};", f"uniform vec3 u_shadow_e2{slot};"]
    behind = _behind(key)  # KHR_materials_transmission, _diffuse_transmission: a punctual light behind the surface
    exits = _behind_exits(key)  # KHR_materials_volume: seen from the exit point, attenuated
    lines += [f"vec3 {name}(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l);" for name, _ in behind]
    lines += [f"vec3 {name}(ShadingFrame f, vec3 wo);" for name in
              dict.fromkeys(name for ends in exits.values() for name in ends if name)]
    lines += ["", "void add_lights(inout vec3 radiance, vec3 position, ShadingFrame f, vec3 wo, bool lit)", "{",
              "    vec3 wi;", "    vec3 irradiance;", "    float n_dot_l;", "    bool valid;"]
    for through, (exit, attenuation) in exits.items():
        lines += [f"    vec3 {through}_exit = {exit}(f, wo);"] if exit else []
        lines += [f"    vec3 {through}_attenuation = {attenuation}(f, wo);"]
        lines += [f"    vec3 {through}_wi;", f"    vec3 {through}_irradiance;", f"    float {through}_n_dot_l;",
                  f"    bool {through}_valid;"] if exit else []

    def term(kind, j, shadow=None):
        """The body after the light's own incident call (and its shadow ``shadow``, an expression)."""
        body = ["        n_dot_l = dot(f.n, wi);",
                "        vec3 term = light_term(material_response(f, wi, wo, n_dot_l), irradiance);",
                "        radiance += (lit && valid && n_dot_l > 0.0) ? term : vec3(0.0);"]
        return body + _behind_lines(behind, exits, lambda at, wi, e: f"{kind}_incident({at}, {j}, {wi}, {e})",
                                    "        ", "radiance", "lit && ", bool(shadow))

    for light in key.lights:
        if light.extended:
            lines += _extended_loop(key, light)
            continue
        if not light.shadowed:
            lines += [f"    for (int j = 0; j < {light.name.upper()}_LIGHT_COUNT; ++j) {{",
                      f"        valid = {light.name}_incident(position, j, wi, irradiance);", *term(light.name, "j"),
                      "    }"]
            continue
        for j in range(light.count):
            lines += ["    {", f"        valid = {light.name}_incident(position, {j}, wi, irradiance);"]
            slot = slots.get((light.name, j))
            shadow = None
            if slot is not None and light.shadow_map == "cube":
                shadow = (f"shadow_cube(u_shadow_map{slot}, u_shadow_origin{slot}, u_shadow_texel{slot}, position, "
                          "shadow_face_normal)")
            elif slot is not None:
                shadow = (f"shadow_ortho(u_shadow_map{slot}, u_shadow_origin{slot}, u_shadow_axis{slot}, "
                          f"u_shadow_e1{slot}, u_shadow_e2{slot}, u_shadow_texel{slot}, position, shadow_face_normal)")
            if shadow and exits:  # the exit's light takes the visibility at the surface (docs/transmission.md)
                lines += [f"        float visibility = {shadow};", "        irradiance *= visibility;"]
            elif shadow:
                lines.append(f"        irradiance *= {shadow};")
            lines += [*term(light.name, j, shadow if exits else None), "    }"]
    lines += ["}"]
    sampled = [_sampled_response(key, light) for light in key.lights if light.extended]
    return "\n".join([line for chunk in sampled for line in chunk] + lines) + "\n"


def transmits(key):
    """Whether ``key``'s program holds glsl/transmission_thin.glsl: a gltf_pbr term with KHR_materials_transmission
    (``GLTF_PBR_TRANSMISSION``) in a per-pixel radiance program that is not a blended layer (`glphong.gpu.transmission`);
    its punctual lights' loops then also add what a light behind the surface sends through it (`_behind`)."""
    return any(name == "gltf_transmission_response" for name, _ in _behind(key))


def _behind(key):
    """``(function, variable)`` of each response to a punctual light behind the surface in ``key``'s program: those
    its terms' models declare (``behind_responses``) under the structural defines the terms carry (`GltfPBR`'s:
    the transmission's BTDF, glsl/transmission_thin.glsl, and the diffuse transmission's,
    glsl/materials/gltf_pbr.glsl)."""
    if key.output != "radiance" or key.shade_per_vertex or key.alpha_blend:
        return []
    return terms_behind(key.terms)


def terms_behind(terms):
    """``(function, variable)`` of each response to a light behind the surface that ``terms`` (`TermKey`) declare:
    their models' ``behind_responses`` under the structural defines the terms carry (`_behind` is a radiance
    program's; `glphong.shaders.builders` asks it before the key is made, for the extended kinds' samples)."""
    return [(name, through) for t in terms for define, name, through in model_named(t.name).behind_responses
            if (define, "1") in t.defines]


def _behind_exits(key):
    """``{variable: (exit, attenuation)}`` of the behind responses that ``key``'s terms' models see from an exit point
    or attenuate (``behind_exits`` under the defines the terms carry: `GltfPBR`'s KHR_materials_volume,
    glsl/transmission_thin.glsl), for the responses `_behind` gives; empty for every other program."""
    throughs = {through for _, through in _behind(key)}
    return {through: (exit, attenuation) for t in key.terms
            for define, through, exit, attenuation in model_named(t.name).behind_exits
            if (define, "1") in t.defines and through in throughs}


def closed_form(term, light):
    """Whether ``term`` (a `TermKey`) reflects the extended ``light`` (a `LightKey`) in closed form (its integral's
    form is one the kind's GLSL offers), else by the kind's weighted directions."""
    return term.integral is not None and term.integral.form in light.integrals


def _sampled_response(key, light):
    """``material_response_<kind>``: the sum of the lit terms that the extended kind's samples carry."""
    sampled = [t for t in key.lit_terms if not closed_form(t, light)]
    if not sampled:
        return []
    lines = [f"// the terms without a closed form under {light.name} lights, summed over its weighted directions",
             f"vec3 material_response_{light.name}(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)", "{",
             "    vec3 response = vec3(0.0);"]
    for t in sampled:
        view = "wo" if "view" in t.needs else "vec3(0.0)"
        call = f"{t.name}_response(f, wi, {view}, n_dot_l)"
        call = f"u_{t.name}_{t.occlusion} * {call}" if light.occludable and t.occlusion else call  # the surroundings
        lines.append(f"    response += {call};")
    return lines + ["    return response;", "}", ""]


def _extended_loop(key, light):
    """The loop over an extended kind's lights (docs/design.md section 13): each closed-form term reflects the
    kind's integral (``k E(n)``, ``k_s`` times the lobe integral about ``r_v``), the others its weighted
    directions; the sum is gated by ``lit`` once.  An occludable kind (the environment): each term's part times its
    occlusion.  A program with responses to a light behind the surface (`_behind`: KHR_materials_transmission,
    _diffuse_transmission) runs the weighted directions whatever its terms and adds, for each response, ``(valid &&
    n.wi < 0) ? light_term(<response>(f, wi, wo, -n.wi), E) : 0``: the kinds' samples do not depend on ``n`` (points
    on the light, the environment's fixed directions over the whole sphere), so those behind are the back
    hemisphere's; not darkened by the occlusion (the surroundings in front, as the background seen through it).  A
    volume (`_behind_exits`): a response with an exit point samples the kind again from ``position + exit``, gated on
    its own ``n.wi' < 0``, and each is times its attenuation, as the punctual loops' (`lights_chunk`)."""
    upper = light.name.upper()
    lines = [f"    for (int j = 0; j < {upper}_LIGHT_COUNT; ++j) {{", "        vec3 reflected = vec3(0.0);"]
    closed = [t for t in key.lit_terms if closed_form(t, light)]
    if any(t.integral.form == "irradiance" for t in closed):
        lines.append(f"        vec3 e_extended = {light.name}_irradiance(position, f.n, j);")
    for t in closed:
        k = f"u_{t.name}_{t.integral.scale}"
        k = k if t.integral.factor == 1.0 else f"({_glsl_float(t.integral.factor)} * {k})"
        k = f"(u_{t.name}_{t.occlusion} * {k})" if light.occludable and t.occlusion else k  # occlusion darkens it
        if t.integral.form == "irradiance":
            lines.append(f"        reflected += {k} * e_extended;")
        else:
            lines.append(f"        reflected += {k} * {light.name}_lobe(position, f.n, reflect(-wo, f.n), "
                         f"u_{t.name}_{t.integral.exponent}, j);")
    sampled = len(closed) < len(key.lit_terms)
    behind = _behind(key)
    if sampled or behind:
        lines += [f"        for (int k = 0; k < {upper}_MAX_SAMPLES; ++k) {{",
                  f"            valid = {light.name}_sample(position, f.n, j, k, wi, irradiance);",
                  "            n_dot_l = dot(f.n, wi);"]
        if sampled:
            lines += [f"            vec3 term = light_term(material_response_{light.name}(f, wi, wo, n_dot_l), irradiance);",
                      "            reflected += (valid && n_dot_l > 0.0) ? term : vec3(0.0);"]
        if behind:
            lines.append("            // behind the surface (n.wi < 0): what each response transmits of the direction")
        # a volume: the direction seen from the exit point, attenuated (as lights_chunk's)
        lines += _behind_lines(behind, _behind_exits(key), lambda at, wi, e: f"{light.name}_sample({at}, f.n, j, k, "
                               f"{wi}, {e})", "            ", "reflected", "", False)
        lines.append("        }")
    return lines + ["        radiance += lit ? reflected : vec3(0.0);", "    }"]


def _behind_lines(behind, exits, incident, pad, total, gate, shadowed):
    """The GLSL lines that add each response to a light behind the surface (`_behind`) to ``total``, for one light
    direction ``wi`` (irradiance ``irradiance``, ``n_dot_l``, ``valid``) of a punctual loop or an extended kind's
    sample loop: ``total += (<gate>valid && n.wi < 0) ? light_term(<response>(f, wi, wo, -n.wi), E) : 0``.  A
    response with an exit (`_behind_exits`: a volume) takes the light again from ``position + <through>_exit``
    (``incident(at, wi, e)``: the kind's own call there; ``shadowed``: its irradiance times the ``visibility`` at
    ``position``), gated on its own ``n.wi' < 0``; one with an attenuation is multiplied by it.  ``pad``: the
    lines' indentation."""
    lines = []
    for name, through in behind:
        exit, attenuation = exits.get(through, (None, None))
        wi, e, n_dot_l, valid = (f"{through}_{v}" if exit else v for v in ("wi", "irradiance", "n_dot_l", "valid"))
        if exit:
            lines.append(f"{pad}{valid} = {incident(f'position + {through}_exit', wi, e)};")
            lines += [f"{pad}{e} *= visibility;"] if shadowed else []
            lines.append(f"{pad}{n_dot_l} = dot(f.n, {wi});")
        scaled = f" * {through}_attenuation" if attenuation else ""
        lines += [f"{pad}vec3 {through} = light_term({name}(f, {wi}, wo, -{n_dot_l}), {e}){scaled};",
                  f"{pad}{total} += ({gate}{valid} && {n_dot_l} < 0.0) ? {through} : vec3(0.0);"]
    return lines


def lod_chunk(key):
    """The generated GLSL of a G-buffer program with textures (label ``generated:levels_of_detail``): one
    sampler per texture size of the object's material (`glphong.shaders.key.lod_slots`), ``u_lod_texture<i>``, and
    ``gbuffer_levels_of_detail(uv)``, their ``surface_texture_lod`` in x, y, z, w (0 beyond)."""
    lines = ["// levels of detail (generated from the program key): what texture() used for each of the object's",
             "// textures, one per texture size (key.py lod_slots); the twin blends the same levels (surface.glsl)"]
    lines += [f"uniform sampler2D u_lod_texture{i};" for i in range(key.lod_textures)]
    lines += ["", "vec4 gbuffer_levels_of_detail(vec2 uv)", "{", "    vec4 lod = vec4(0.0);"]
    lines += [f"    lod.{'xyzw'[i]} = surface_texture_lod(u_lod_texture{i}, uv);" for i in range(key.lod_textures)]
    lines += ["    return lod;", "}"]
    return "\n".join(lines) + "\n"
