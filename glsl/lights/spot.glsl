// lights/spot.glsl -- the spot light of KHR_lights_punctual (docs/design.md section 11; glphong/lights/spot.py).
//
// spot_incident(x, j, out wi, out E) -> valid
//   wi = (p_j - x) / d,  d = |p_j - x|                      by safe_normalize
//   KHR_lights_punctual's angular falloff, with theta the angle between -wi and the axis a_j:
//     s = 1 / max(0.001, cos(inner) - cos(outer)),  o = -cos(outer) s,  f = clamp(cos(theta) s + o, 0, 1)^2
//   evaluated in the chord form of docs/design.md section 3: cos(theta) = 1 - delta with
//     delta = |-wi - a_j|^2 / 2  (exact to a few ulps of itself even for theta ~ 1e-6 rad, where cos(theta)
//     rounds to 1 in float32),  and  f = clamp((versin_outer - delta) s, 0, 1)^2,
//   versin_outer = 1 - cos(outer) = 2 sin^2(outer / 2) and s computed on the host in float64, so the
//   difference versin_outer - delta is exact near the cone's edge (Sterbenz) instead of cancelling two
//   products of size s.
//   E = min((I_j (g / d)) (g / d), FLT_MAX),  g = clamp((versin_outer - delta) s, 0, 1)   [W/m^2]
//     (= f I / d^2; g / d never overflows or flushes where E is representable, as (I / d) / d for points)
//   times range_window(d, range_j) where SPOT_RANGE (some spot light of the scene has a range).
//   Units: I_j [W/sr] along the axis; d, range [m]; a_j unit, the direction the light points in.
// Key defines read here: SPOT_RANGE, NAIVE_LIGHT (wi by plain_normalize where the key proves it safe, common.glsl).

bool spot_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)
{
    float d;
#if NAIVE_LIGHT
    bool valid = plain_normalize(u_spot_position[j] - x, wi, d);
#else
    bool valid = safe_normalize(u_spot_position[j] - x, wi, d);
#endif
    vec3 chord = -wi - u_spot_axis[j];
    float delta = 0.5 * dot(chord, chord);
    float g = clamp((u_spot_versin_outer[j] - delta) * u_spot_scale[j], 0.0, 1.0);
    float g_d = g / d;
    irradiance = min((u_spot_intensity[j] * g_d) * g_d, vec3(FLT_MAX));
#if defined(SPOT_RANGE)
    irradiance = u_spot_range[j] > 0.0 ? irradiance * range_window(d, u_spot_range[j]) : irradiance;
#endif
    return valid;
}
