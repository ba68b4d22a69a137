// materials/gltf_pbr.glsl -- the model 'gltf_pbr': glTF 2.0's metallic-roughness material as its specification's
// Appendix B writes it (docs/design.md section 9; glphong/materials/gltf_pbr.py), branchless, never NaN or Inf.
//
//   alpha = roughness^2;  x = (1 - |v.h|)^5
//   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)                                   GGX (Trowbridge-Reitz)
//   V = 1 / (2 (|n.v| sqrt(alpha^2 + (1 - alpha^2)(n.l)^2) + |n.l| sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))
//                                                                                   height-correlated Smith
//   metal = (c + (1 - c) x) V D;   dielectric = mix(c/pi, V D, f0 + (1 - f0) x);   c = base_color
//   f0 = ((ior - 1)/(ior + 1))^2 (KHR_materials_ior; the core specification's ior 1.5 gives 0.04)
//   f_r = mix(dielectric, metal, metallic);   response = f_r (n.l)
//
// microfacet_geometry (library chunk microfacet.glsl): valid, n.v, n.h, v.h = |l + v|/2, tan2 = tan^2(theta_h) from the
//   chord (no 1 - (n.h)^2 cancellation at the peak); invalid where l = -v, n.v <= 0 or n.l <= 0 (the response is 0).
// microfacet_ggx(tan2, a2) (library chunk microfacet.glsl) -> GGX D = (a2 r) r / pi, r = (1 + tan2)/(a2 + tan2): the
//   specification's D divided through by (n.h)^4; 0 where a2 + tan2 = 0 (roughness 0 at the exact mirror direction:
//   a delta that no point light meets with nonzero measure, so this program reflects none of it).
// gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2) -> V (n.l) = n.l / (2 (n.v r_l + n.l r_v)),
//   r_x = sqrt((n.x)^2 + a2 (1 - (n.x)^2)): the response's n.l cancels the 1/(n.l) of V, so a grazing light
//   never forms 1/(n.l); at most 1 / (4 n.v) for roughness 0.
// KHR_materials_specular (GLTF_PBR_SPECULAR; glphong/materials/gltf_extensions.py, docs/gltf_extensions.md):
//   gltf_specular_fresnel(f0, specular, specular_color, x) -> F_d = mix(min(f0 specular_color, 1) specular, specular, x)
//   (rgb): the dielectric = F_d V D + (1 - max(F_d.r, F_d.g, F_d.b)) c/pi; the metal unchanged.
// KHR_materials_clearcoat (GLTF_PBR_CLEARCOAT): gltf_clearcoat_fresnel(n_dot_v) -> F_c = 0.04 + 0.96 (1 - n.v)^5
//   (fresnel_coat with ior 1.5, on n.v); f_r = mix(f_r, V_c D_c, clearcoat F_c), alpha_c = clearcoat_roughness^2, the
//   coat's normal the shading normal n.
// Uniforms (declared by glphong from the model's params): u_gltf_pbr_base_color, u_gltf_pbr_metallic,
// u_gltf_pbr_roughness, u_gltf_pbr_ior, u_gltf_pbr_specular, u_gltf_pbr_specular_color, u_gltf_pbr_clearcoat,
// u_gltf_pbr_clearcoat_roughness (u_gltf_pbr_emissive and u_gltf_pbr_occlusion are read by generated code).
// Key defines read here: GLTF_PBR_SPECULAR, GLTF_PBR_CLEARCOAT (defined where the material uses the extension: its code
// is not in the program otherwise).

const float GLTF_PBR_INV_PI = 0.3183098861837907;

float gltf_pbr_visibility_cos(float n_dot_l, float n_dot_v, float a2)
{
    float r_l = sqrt(n_dot_l * n_dot_l + a2 * (1.0 - n_dot_l * n_dot_l));
    float r_v = sqrt(n_dot_v * n_dot_v + a2 * (1.0 - n_dot_v * n_dot_v));
    return n_dot_l / (2.0 * (n_dot_v * r_l + n_dot_l * r_v));
}

#if defined(GLTF_PBR_SPECULAR)
vec3 gltf_specular_fresnel(float f0, float specular, vec3 specular_color, float x)
{
    vec3 dielectric_f0 = min(f0 * specular_color, vec3(1.0)) * specular;
    return dielectric_f0 + (specular - dielectric_f0) * x;
}
#endif

#if defined(GLTF_PBR_CLEARCOAT)
float gltf_clearcoat_fresnel(float n_dot_v)
{
    float y1 = max(1.0 - n_dot_v, 0.0);
    float y = (y1 * y1) * (y1 * y1) * y1;
    return 0.04 + 0.96 * y;
}
#endif

vec3 gltf_pbr_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    float n_dot_v, n_dot_h, v_dot_h, tan2;
    bool valid = microfacet_geometry(f.n, wi, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, tan2);
    float alpha = u_gltf_pbr_roughness * u_gltf_pbr_roughness;
    float a2 = alpha * alpha;
    // roughness 0: D is a delta (0 for a point light); V's r_x would underflow to 0/0 for grazing l and v
    float specular = a2 > 0.0 ? min(microfacet_ggx(tan2, a2) * gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2), FLT_MAX)
                              : 0.0;
    float x1 = max(1.0 - v_dot_h, 0.0);                   // v.h = |l + v|/2 may round above 1
    float x = (x1 * x1) * (x1 * x1) * x1;
    vec3 c = u_gltf_pbr_base_color;
    float m = u_gltf_pbr_metallic;
    float r = (u_gltf_pbr_ior - 1.0) / (u_gltf_pbr_ior + 1.0);  // KHR_materials_ior: f0 = ((ior - 1)/(ior + 1))^2
    float f0 = r * r;
#if defined(GLTF_PBR_SPECULAR)  // KHR_materials_specular: an rgb F_d, the diffuse weighted by 1 - max(F_d)
    vec3 fd = gltf_specular_fresnel(f0, u_gltf_pbr_specular, u_gltf_pbr_specular_color, x);
    float fd_max = max(fd.r, max(fd.g, fd.b));
#else
    float fd = f0 + (1.0 - f0) * x;
    float fd_max = fd;
#endif
    // mix(dielectric, metal, m) = (c/pi)(n.l)(1 - fd)(1 - m) + [fd (1 - m) + (c + (1 - c) x) m] V D (n.l)
    vec3 diffuse = (c * (GLTF_PBR_INV_PI * n_dot_l)) * (1.0 - fd_max) * (1.0 - m);
    vec3 fresnel = fd * (1.0 - m) + (c + (1.0 - c) * x) * m;
    vec3 value = diffuse + fresnel * specular;
#if defined(GLTF_PBR_CLEARCOAT)  // KHR_materials_clearcoat: mix(f_r, V_c D_c, clearcoat F_c(n.v)), times n.l
    float alpha_c = u_gltf_pbr_clearcoat_roughness * u_gltf_pbr_clearcoat_roughness;
    float a2_c = alpha_c * alpha_c;
    // roughness 0: the coat is a delta (0 for a point light), and V's r_x would underflow to 0/0 at grazing
    float coat = a2_c > 0.0 ? min(microfacet_ggx(tan2, a2_c) * gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2_c),
                                  FLT_MAX) : 0.0;
    float coat_weight = u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_v);
    value = value * (1.0 - coat_weight) + coat_weight * coat;
#endif
    return valid ? value : vec3(0.0);
}
