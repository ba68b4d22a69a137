// lights/unattenuated.glsl -- the lecture's assignment light: a position and a value L_i used as E at every
// distance (docs/design.md E2, section 11; glphong/lights/unattenuated.py).
//
// unattenuated_incident(x, j, out wi, out E) -> valid
//   wi = (p_j - x) / |p_j - x|  by safe_normalize;  E = L_i,j [W/m^2], no falloff.
// Key defines read here: NAIVE_LIGHT (wi by plain_normalize where the key proves it safe, common.glsl).

bool unattenuated_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)
{
    float d;
#if NAIVE_LIGHT
    bool valid = plain_normalize(u_unattenuated_position[j] - x, wi, d);
#else
    bool valid = safe_normalize(u_unattenuated_position[j] - x, wi, d);
#endif
    irradiance = u_unattenuated_radiance[j];
    return valid;
}
