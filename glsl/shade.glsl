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
// Each light kind is a loop of compile-time length; a kind the scene lacks has no loop at all.
// Light j contributes nothing unless n.l_j > 0 (and its direction normalises): every light's term is
// computed and the gate selects it, without a branch.  llvmpipe (and a GPU's SIMD group) runs both sides
// of a branch under a mask, so an `if`/`continue` saves nothing and costs control flow; written as
// selects the same arithmetic measured 0.59x to 0.70x the frame time of the branching version on the
// six gallery tiles at 1024x1024 (EGL, one run), with bit-identical images on EGL and OSMesa.  A term's response may therefore be
// computed where n.l <= 0 and discarded: it must not loop forever there, but NaN or Inf is harmless.
// The view vector v is computed only where a term reads it (NEEDS_VIEW).
// The uber-shader reads its light counts from uniforms (*_LIGHT_COUNT).
//
// Key defines read here: NEEDS_VIEW, NUM_{POINT,UNATTENUATED,DIRECTIONAL}_LIGHTS (array sizes) and
// {POINT,UNATTENUATED,DIRECTIONAL}_LIGHT_COUNT (loop bounds).

#if NUM_POINT_LIGHTS > 0
uniform vec3 u_point_position[NUM_POINT_LIGHTS];        // [m]
uniform vec3 u_point_intensity[NUM_POINT_LIGHTS];       // Phi / (4 pi) [W/sr]
#endif
#if NUM_UNATTENUATED_LIGHTS > 0
uniform vec3 u_unattenuated_position[NUM_UNATTENUATED_LIGHTS];  // [m]
uniform vec3 u_unattenuated_radiance[NUM_UNATTENUATED_LIGHTS];  // L_i, used as E [W/m^2]
#endif
#if NUM_DIRECTIONAL_LIGHTS > 0
uniform vec3 u_directional_direction[NUM_DIRECTIONAL_LIGHTS];   // unit, toward the light
uniform vec3 u_directional_irradiance[NUM_DIRECTIONAL_LIGHTS];  // E [W/m^2]
#endif

vec3 light_term(vec3 response, vec3 irradiance)
{
    return mix(response * irradiance, vec3(0.0), equal(irradiance, vec3(0.0)));
}

vec3 shade_point(vec3 position, ShadingFrame f, bool n_valid, vec4 eye)
{
    vec3 radiance = material_emission();
#if NUM_POINT_LIGHTS > 0 || NUM_UNATTENUATED_LIGHTS > 0 || NUM_DIRECTIONAL_LIGHTS > 0
    bool lit = n_valid;
    vec3 wo = vec3(0.0);
#if NEEDS_VIEW
    float view_distance;
    lit = lit && safe_normalize(eye.xyz - position * eye.w, wo, view_distance);
#endif
    vec3 wi;
    float d;
    float n_dot_l;
    bool valid;
#endif
#if NUM_POINT_LIGHTS > 0
    for (int j = 0; j < POINT_LIGHT_COUNT; ++j) {
        valid = safe_normalize(u_point_position[j] - position, wi, d);
        n_dot_l = dot(f.n, wi);
        vec3 term = light_term(material_response(f, wi, wo, n_dot_l), point_irradiance(u_point_intensity[j], d));
        radiance += (lit && valid && n_dot_l > 0.0) ? term : vec3(0.0);
    }
#endif
#if NUM_UNATTENUATED_LIGHTS > 0
    for (int j = 0; j < UNATTENUATED_LIGHT_COUNT; ++j) {
        valid = safe_normalize(u_unattenuated_position[j] - position, wi, d);
        n_dot_l = dot(f.n, wi);
        vec3 term = light_term(material_response(f, wi, wo, n_dot_l), u_unattenuated_radiance[j]);
        radiance += (lit && valid && n_dot_l > 0.0) ? term : vec3(0.0);
    }
#endif
#if NUM_DIRECTIONAL_LIGHTS > 0
    for (int j = 0; j < DIRECTIONAL_LIGHT_COUNT; ++j) {
        wi = u_directional_direction[j];
        n_dot_l = dot(f.n, wi);
        vec3 term = light_term(material_response(f, wi, wo, n_dot_l), u_directional_irradiance[j]);
        radiance += (lit && n_dot_l > 0.0) ? term : vec3(0.0);
    }
#endif
    return radiance;
}
