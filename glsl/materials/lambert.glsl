// materials/lambert.glsl -- the model 'lambert': ideal diffuse reflection (docs/design.md E3).
//
// lambert(kd, n_dot_l) -> kd (n.l)
//   kd: BRDF value [1/sr] per RGB channel (an albedo rho is kd = rho / pi);
//   n_dot_l: cos(theta_i) of the unit normal and unit light direction, > 0 (the caller gates it).
// lambert_response(f, wi, wo, n_dot_l) -> f_r (n.l) = u_lambert_kd (n.l)   [1/sr], f_r = kd.
//   Multiplied by the irradiance E [W/m^2] it gives the reflected radiance [W/(m^2 sr)].
// Uniforms (declared by glphong from the model's params): u_lambert_kd.

vec3 lambert(vec3 kd, float n_dot_l)
{
    return kd * n_dot_l;
}

vec3 lambert_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    return lambert(u_lambert_kd, n_dot_l);
}
