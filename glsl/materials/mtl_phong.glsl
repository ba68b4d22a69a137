// materials/mtl_phong.glsl -- the model 'mtl_phong': the Wavefront MTL material (illum 1 and 2), the
// lecture's Phong with MTL's own ambient coefficient (docs/design.md E6).
//
// mtl_phong_response(f, wi, wo, n_dot_l) -> Kd (n.l) + Ks max(v.r, 0)^Ns   [1/sr], times cos
//   Kd, Ks: MTL's diffuse and specular colours, used as the lecture's k_d and k_s (an MTL file means
//   colour = Ka L_a + Kd (n.l) E + Ks (v.r)^Ns E, the fixed-function Phong its authors saw);
//   Ns: MTL's specular exponent (0 to 1000) as q; the lobe is lobe.glsl's stable phong_lobe.
// Its answer to the ambient light is Ka L_a (the model's ambient parameter kamb), not Kd L_a as Lambert's.
// Uniforms (declared by glphong from the model's params): u_mtl_phong_kd, u_mtl_phong_ks, u_mtl_phong_q,
// u_mtl_phong_kamb.

vec3 mtl_phong_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    return u_mtl_phong_kd * n_dot_l + u_mtl_phong_ks * phong_lobe(f.n, wi, wo, u_mtl_phong_q);
}
