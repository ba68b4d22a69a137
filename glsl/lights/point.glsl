// lights/point.glsl -- the point light (docs/design.md E1, section 11; glphong/lights/point.py).
//
// point_incident(x, j, out wi, out E) -> valid
//   wi = (p_j - x) / |p_j - x|  by safe_normalize (valid: the difference is finite and non-zero)
//   E  = I_j / d^2  by point_irradiance (I_j = Phi_j / (4 pi) [W/sr], d = |p_j - x| [m])
//   times range_window(d, range_j) where POINT_RANGE (some point light of the scene has a range; a
//   light without one has range_j = 0 and keeps E: a select, no branch).
// Key defines read here: POINT_RANGE, NAIVE_LIGHT (wi by plain_normalize where the key proves it safe, common.glsl).

bool point_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)
{
    float d;
#if NAIVE_LIGHT
    bool valid = plain_normalize(u_point_position[j] - x, wi, d);
#else
    bool valid = safe_normalize(u_point_position[j] - x, wi, d);
#endif
    irradiance = point_irradiance(u_point_intensity[j], d);
#if defined(POINT_RANGE)
    irradiance = u_point_range[j] > 0.0 ? irradiance * range_window(d, u_point_range[j]) : irradiance;
#endif
    return valid;
}
