// lambert.glsl -- ideal diffuse reflection (DESIGN E3).
//
// lambert(kd, n_dot_l) -> kd (n.l)
//   kd: BRDF value [1/sr] per RGB channel (an albedo rho is kd = rho / pi);
//   n_dot_l: cos(theta_i) of the unit normal and unit light direction, > 0 (the caller gates it).
//   Multiplied by the irradiance E [W/m^2] it gives the reflected radiance [W/(m^2 sr)].

vec3 lambert(vec3 kd, float n_dot_l)
{
    return kd * n_dot_l;
}
