// shade.glsl -- the whole local-illumination model (docs/design.md E6, section 8), specialised by the program key.
//
//   L = material_emission() + sum_j [n.l_j > 0] material_response(f, l_j, v, n.l_j) E_j
//
// material_emission() and material_response() are generated from the key (the material chunk):
// k_a plus each term's answer to L_a, and the sum of the terms' <model>_response() [1/sr, times cos].
// shade_point(position, f, n_valid, eye) -> L [W/(m^2 sr)], RGB, linear, never clamped
//   position: world-space surface point [m];  f: the ShadingFrame (n_valid false: emission only);
//   eye: the homogeneous eye (e, w): the view vector is v = normalize(e - w x); a perspective camera's
//   centre [m] with w = 1, an orthographic camera's backward axis with w = 0 (x * 1.0 is exact: the
//   perspective arithmetic is unchanged).
// light_term(response, E) -> response * E, exactly 0 where E = 0 (a response that overflowed to Inf
//   times an irradiance of 0 would be NaN): a select, no branch.
// The loops over the lights are generated from the key (generated:lights, glphong/shaders/generated.py):
// one loop of compile-time length per light kind present, calling the kind's <kind>_incident(x, j, wi, E)
// (glsl/lights/<kind>.glsl, docs/design.md section 11); a kind the scene lacks has no loop and no chunk.
// Light j contributes nothing unless n.l_j > 0 (and its direction normalises): every light's term is
// computed and the gate selects it, without a branch.  llvmpipe (and a GPU's SIMD group) runs both sides
// of a branch under a mask, so an `if`/`continue` saves nothing and costs control flow; written as
// selects the same arithmetic measured 0.59x to 0.70x the frame time of the branching version on the
// six gallery tiles at 1024x1024 (EGL, one run), with bit-identical images on EGL and OSMesa.  A term's response may therefore be
// computed where n.l <= 0 and discarded: it must not loop forever there, but NaN or Inf is harmless.
// The view vector v is computed only where a term reads it (NEEDS_VIEW).
// The uber-shader reads its light counts from uniforms (<KIND>_LIGHT_COUNT).
//
// Key defines read here: NEEDS_VIEW, NAIVE_VIEW (v by plain_normalize where the key proves it safe, common.glsl), NUM_LIGHTS (the total over the kinds).

#if NUM_LIGHTS > 0
// the loops over the program's light kinds, generated from the key (generated:lights, after this chunk)
void add_lights(inout vec3 radiance, vec3 position, ShadingFrame f, vec3 wo, bool lit);
#endif

vec3 light_term(vec3 response, vec3 irradiance)
{
    return mix(response * irradiance, vec3(0.0), equal(irradiance, vec3(0.0)));
}

vec3 shade_point(vec3 position, ShadingFrame f, bool n_valid, vec4 eye)
{
    vec3 radiance = material_emission();
#if NUM_LIGHTS > 0
    bool lit = n_valid;
    vec3 wo = vec3(0.0);
#if NEEDS_VIEW
    float view_distance;
#if NAIVE_VIEW
    lit = lit && plain_normalize(eye.xyz - position * eye.w, wo, view_distance);
#else
    lit = lit && safe_normalize(eye.xyz - position * eye.w, wo, view_distance);
#endif
#endif
    add_lights(radiance, position, f, wo, lit);
#endif
    return radiance;
}
