// shade.glsl -- the whole local-illumination model (DESIGN E6), specialised by the program key.
//
//   L = k_a + k_d L_a + sum_j [n.l_j > 0] (k_d (n.l_j) + k_s lobe_j) E_j
//
// light_response(n, wi, wo, n_dot_l) -> k_d (n.l) + k_s lobe          (the bracket, [1/sr] times cos)
// shade_point(position, n, n_valid, eye) -> L [W/(m^2 sr)], RGB, linear, never clamped
//   position: world-space surface point [m];  n: unit normal (n_valid false: ambient terms only);
//   eye: world-space camera centre [m].
// Each light kind is a loop of compile-time length; a kind the scene lacks has no loop at all.
// Light j contributes nothing unless n.l_j > 0 (tested before anything else is evaluated).
//
// The view vector v is computed only where a specular lobe reads it (NEEDS_VIEW).
// The uber-shader (uber.glsl before this chunk) compiles every term and reads SWITCH(u_use_*)
// flags, its lobe (SPECULAR_LOBE = uber_lobe) and the *_LIGHT_COUNT light counts from uniforms.
//
// Key defines read here: HAS_KA, HAS_KD_LA, HAS_DIFFUSE, HAS_SPECULAR, NEEDS_VIEW, SPECULAR_LOBE,
// SWITCH(flag), NUM_{POINT,UNATTENUATED,DIRECTIONAL}_LIGHTS (array sizes) and
// {POINT,UNATTENUATED,DIRECTIONAL}_LIGHT_COUNT (loop bounds).

#if HAS_KA
uniform vec3 u_ka;                 // [W/(m^2 sr)]
#endif
#if HAS_DIFFUSE || HAS_KD_LA
uniform vec3 u_kd;                 // [1/sr]
#endif
#if HAS_KD_LA
uniform vec3 u_ambient;            // L_a [W/m^2]
#endif
#if HAS_SPECULAR
uniform vec3 u_ks;                 // [1/sr]
uniform float u_q;                 // exponent >= 0
#endif
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

vec3 light_response(vec3 n, vec3 wi, vec3 wo, float n_dot_l)
{
    vec3 f = vec3(0.0);
#if HAS_DIFFUSE
    if (SWITCH(u_use_diffuse)) f += lambert(u_kd, n_dot_l);
#endif
#if HAS_SPECULAR
    f += u_ks * SPECULAR_LOBE(n, wi, wo, u_q);
#endif
    return f;
}

vec3 shade_point(vec3 position, vec3 n, bool n_valid, vec3 eye)
{
    vec3 radiance = vec3(0.0);
#if HAS_KA
    if (SWITCH(u_use_ka)) radiance += u_ka;
#endif
#if HAS_KD_LA
    if (SWITCH(u_use_kd_la)) radiance += u_kd * u_ambient;
#endif
#if NUM_POINT_LIGHTS > 0 || NUM_UNATTENUATED_LIGHTS > 0 || NUM_DIRECTIONAL_LIGHTS > 0
    if (!n_valid) {
        return radiance;
    }
    vec3 wo = vec3(0.0);
#if NEEDS_VIEW
    float view_distance;
    if (!safe_normalize(eye - position, wo, view_distance)) {
        return radiance;
    }
#endif
    vec3 wi;
    float d;
    float n_dot_l;
#endif
#if NUM_POINT_LIGHTS > 0
    for (int j = 0; j < POINT_LIGHT_COUNT; ++j) {
        if (!safe_normalize(u_point_position[j] - position, wi, d)) continue;
        n_dot_l = dot(n, wi);
        if (!(n_dot_l > 0.0)) continue;
        radiance += light_response(n, wi, wo, n_dot_l) * point_irradiance(u_point_intensity[j], d);
    }
#endif
#if NUM_UNATTENUATED_LIGHTS > 0
    for (int j = 0; j < UNATTENUATED_LIGHT_COUNT; ++j) {
        if (!safe_normalize(u_unattenuated_position[j] - position, wi, d)) continue;
        n_dot_l = dot(n, wi);
        if (!(n_dot_l > 0.0)) continue;
        radiance += light_response(n, wi, wo, n_dot_l) * u_unattenuated_radiance[j];
    }
#endif
#if NUM_DIRECTIONAL_LIGHTS > 0
    for (int j = 0; j < DIRECTIONAL_LIGHT_COUNT; ++j) {
        wi = u_directional_direction[j];
        n_dot_l = dot(n, wi);
        if (!(n_dot_l > 0.0)) continue;
        radiance += light_response(n, wi, wo, n_dot_l) * u_directional_irradiance[j];
    }
#endif
    return radiance;
}
