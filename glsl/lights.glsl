// lights.glsl -- library of the light kinds: irradiance of a point source and the glTF range window
// (docs/design.md E1, section 11).
//
// point_irradiance(intensity, d) -> E           E1:  E = Phi / (4 pi d^2)
//   evaluated as min((I / d) / d, FLT_MAX) with I = Phi / (4 pi) [W/sr] computed on the host in
//   float64, so d^2 is never formed (d from 1e-19 to 1e19 stays finite and correctly scaled), and
//   an irradiance beyond float32 saturates at FLT_MAX instead of becoming Inf (Inf times a zero
//   coefficient channel would be NaN).
//   intensity: vec3 [W/sr];  d: distance [m] (> 0);  E: vec3 [W/m^2].
//   NAIVE_FALLOFF (the textbook formulation: with NAIVE, or where the key proves d^2 and I / d^2 within
//   float32's normal range, docs/design.md section 3): I / (d * d).
// range_window(d, range) -> w in [0, 1]     KHR_lights_punctual:  w = clamp(1 - (d / range)^4, 0, 1)
//   (the specification's window, not its square as three.js and Filament use), evaluated as
//   t = d / range;  w = clamp(((range - d) / range) (1 + t) (1 + t^2), 0, 1)
//   since 1 - t^4 = (1 - t)(1 + t)(1 + t^2): range - d is exact where d is within a factor 2 of range
//   (Sterbenz), so w keeps its relative accuracy as d -> range instead of cancelling in 1 - t^4.
//   d, range: [m] (range > 0);  w dimensionless.
// Key defines read here: NAIVE_FALLOFF.

#if NAIVE_FALLOFF
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

float range_window(float d, float range)
{
    float t = d / range;
    return clamp(((range - d) / range) * (1.0 + t) * (1.0 + t * t), 0.0, 1.0);
}
