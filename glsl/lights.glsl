// lights.glsl -- irradiance delivered by one light (docs/design.md E1, E2).
//
// point_irradiance(intensity, d) -> E           E1:  E = Phi / (4 pi d^2)
//   evaluated as min((I / d) / d, FLT_MAX) with I = Phi / (4 pi) [W/sr] computed on the host in
//   float64, so d^2 is never formed (d from 1e-19 to 1e19 stays finite and correctly scaled), and
//   an irradiance beyond float32 saturates at FLT_MAX instead of becoming Inf (Inf times a zero
//   coefficient channel would be NaN).
//   intensity: vec3 [W/sr];  d: distance [m] (> 0);  E: vec3 [W/m^2].
//   NAIVE (the textbook formulation, for the stability report only): I / (d * d).
// Lights given directly by L_i (E2) and directional lights use their value as E unchanged.
// Key defines read here: NAIVE.

#if NAIVE
vec3 point_irradiance(vec3 intensity, float d)
{
    return intensity / (d * d);
}
#else
vec3 point_irradiance(vec3 intensity, float d)
{
    return min((intensity / d) / d, vec3(FLT_MAX));
}
#endif
