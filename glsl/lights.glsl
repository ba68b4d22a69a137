// lights.glsl -- irradiance delivered by one light (DESIGN E1, E2).
//
// point_irradiance(intensity, d) -> E           E1:  E = Phi / (4 pi d^2)
//   evaluated as (I / d) / d with I = Phi / (4 pi) [W/sr] computed on the host in float64,
//   so d^2 is never formed: d from 1e-19 to 1e19 stays finite and correctly scaled.
//   intensity: vec3 [W/sr];  d: distance [m] (> 0);  E: vec3 [W/m^2].
// Lights given directly by L_i (E2) and directional lights use their value as E unchanged.

vec3 point_irradiance(vec3 intensity, float d)
{
    return (intensity / d) / d;
}
