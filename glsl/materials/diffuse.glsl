// materials/diffuse.glsl -- the model 'diffuse': Lambert's ideal diffuse reflection parameterised by its
// albedo (docs/design.md section 9: the rho_d / pi term of the normalised and physically based models).
//
// diffuse_response(f, wi, wo, n_dot_l) -> u_diffuse_rho_d (n.l / pi)      [1/sr]
//   f_r = rho_d / pi, so the directional albedo is rho_d at every incident angle.
// Uniforms (declared by glphong from the model's params): u_diffuse_rho_d.

const float DIFFUSE_INV_PI = 0.3183098861837907;

vec3 diffuse_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    return u_diffuse_rho_d * (n_dot_l * DIFFUSE_INV_PI);
}
