// materials/gltf_iridescence.glsl -- KHR_materials_iridescence on the model 'gltf_pbr': the thin-film Fresnel of
// Belcour & Barla (2017) as the extension's README writes it (glphong/materials/gltf_iridescence.py,
// docs/gltf_extensions.md). Read before materials/gltf_pbr.glsl in the model's chunk, all of it under the define.
//
//   d = mix(iridescence_thickness_minimum, iridescence_thickness_maximum, iridescence_thickness_mix)   [nm]
//   eta1 = 1 (outside), eta2 = iridescence_ior (the film), cos1 = v.h (the Fresnel's angle in Appendix B)
//   cos2 = sqrt(1 - (eta1/eta2)^2 (1 - cos1^2)) (Snell; F = 1 where cos2^2 < 0, total internal reflection), formed as
//     (1 - (eta1/eta2)^2) + (eta1/eta2)^2 cos1^2: at grazing light the README's 1 - cos1^2 loses cos1^2 in float32 (a film
//     of ior 1, cos1 = 1e-3: cos2 6 % off, and the phase of a 1e5 nm film with it)
//   R12 = Schlick(((eta2 - eta1)/(eta2 + eta1))^2, cos1), T121 = 1 - R12, phi21 = pi - (eta2 < eta1 ? pi : 0)
//   eta3 = (1 + sqrt(f))/(1 - sqrt(f)), f = min(base_f0 + 1e-4, 0.9999) (the README's guard "+ 0.0001"; the min is
//     glphong's: at base_f0 >= 0.9998 the README's eta3 is infinite or negative); R23 = Schlick(((eta3 - eta2)/(eta3 +
//     eta2))^2, cos2), phi23 = eta3 < eta2 ? pi : 0, per channel; phi = phi21 + phi23;  OPD = 2 eta2 d cos2  [nm]
//   R123 = clamp(R12 R23, 1e-5, 0.9999), Rs = T121^2 R23 / (1 - R123), C_m = (Rs - T121) R123^(m/2)
//   F_iridescence = max(R12 + Rs + sum_{m=1,2} C_m 2 S(m OPD, m phi), 0)                                  rgb
//   S(OPD, shift) = XYZ_TO_REC709 (xyz / 1.0685e-7), xyz_i = val_i sqrt(2 pi var_i) cos(pos_i t + shift_i)
//     exp(-var_i t^2), t = 2 pi OPD 1e-9, and a fourth Gaussian added to x: the README's Gaussian fit of the CIE 1931
//     sensitivities in Fourier space ("evalSensitivity"), measured against a spectral integral in docs/gltf_extensions.md.
//   Schlick(r0, c) = r0 + (1 - r0)(1 - c)^5; the README's IorToFresnel0 squares by a product (pow(x, 2.0) of a
//   negative x is undefined in GLSL).
// gltf_iridescence_parts(c, m, x, film_f0, F_d, v.h, out fd_max, out fresnel): the dielectric's Fresnel F_d' =
//   mix(F_d, F_iridescence(base_f0 = film_f0), iridescence), film_f0 = min(f0 specular_color, 1) specular (or f0
//   without KHR_materials_specular: the response's gltf_specular_fresnel at x = 0), fd_max = max(F_d'), the response's
//   diffuse weight 1 - max(F_d') (the README's rgb_mix); fresnel = F_d' (1 - m) + mix(c + (1 - c) x,
//   F_iridescence(base_f0 = c), iridescence) m; response = c/pi (n.l)(1 - fd_max)(1 - m) + fresnel V D.
// Uniforms: u_gltf_pbr_iridescence, u_gltf_pbr_iridescence_ior, u_gltf_pbr_iridescence_thickness_minimum,
// u_gltf_pbr_iridescence_thickness_maximum, u_gltf_pbr_iridescence_thickness_mix.
// Key defines read here: GLTF_PBR_IRIDESCENCE (the material uses the extension: nothing here is compiled otherwise).

#if defined(GLTF_PBR_IRIDESCENCE)
const float GLTF_IRIDESCENCE_PI = 3.141592653589793;
const mat3 GLTF_IRIDESCENCE_XYZ_TO_REC709 = mat3(
     3.2404542, -0.9692660,  0.0556434,
    -1.5371385,  1.8760108, -0.2040259,
    -0.4985314,  0.0415560,  1.0572252);

vec3 gltf_iridescence_sensitivity(float opd, vec3 shift)
{
    float phase = 2.0 * GLTF_IRIDESCENCE_PI * opd * 1.0e-9;
    vec3 val = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    vec3 pos = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);
    vec3 var = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);
    vec3 xyz = val * sqrt(2.0 * GLTF_IRIDESCENCE_PI * var) * cos(pos * phase + shift) * exp(-(phase * phase) * var);
    xyz.x += 9.7470e-14 * sqrt(2.0 * GLTF_IRIDESCENCE_PI * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x)
             * exp(-4.5282e+09 * (phase * phase));
    xyz /= 1.0685e-7;
    return GLTF_IRIDESCENCE_XYZ_TO_REC709 * xyz;
}

vec3 gltf_iridescence_fresnel(float outside_ior, float film_ior, vec3 base_f0, float thickness, float cos_theta1)
{
    float ratio = outside_ior / film_ior;
    float cos2_theta2 = (1.0 - ratio * ratio) + ratio * ratio * (cos_theta1 * cos_theta1);  // no 1 - cos^2 at grazing
    float cos_theta2 = sqrt(max(cos2_theta2, 0.0));
    // first interface
    float q0 = (film_ior - outside_ior) / (film_ior + outside_ior);
    float y1 = max(1.0 - cos_theta1, 0.0);
    float r12 = q0 * q0 + (1.0 - q0 * q0) * ((y1 * y1) * (y1 * y1) * y1);
    float t121 = 1.0 - r12;
    float phi12 = film_ior < outside_ior ? GLTF_IRIDESCENCE_PI : 0.0;
    float phi21 = GLTF_IRIDESCENCE_PI - phi12;
    // second interface
    vec3 s = sqrt(min(base_f0 + 0.0001, vec3(0.9999)));
    vec3 base_ior = (1.0 + s) / (1.0 - s);
    vec3 q1 = (base_ior - film_ior) / (base_ior + film_ior);
    float y2 = max(1.0 - cos_theta2, 0.0);
    vec3 r23 = q1 * q1 + (1.0 - q1 * q1) * ((y2 * y2) * (y2 * y2) * y2);
    vec3 phi23 = vec3(base_ior.x < film_ior ? GLTF_IRIDESCENCE_PI : 0.0, base_ior.y < film_ior ? GLTF_IRIDESCENCE_PI : 0.0,
                      base_ior.z < film_ior ? GLTF_IRIDESCENCE_PI : 0.0);
    // phase shift, compound terms, the Airy sum's terms m = 0, 1, 2 in Fourier space
    float opd = 2.0 * film_ior * thickness * cos_theta2;
    vec3 phi = vec3(phi21) + phi23;
    vec3 r123 = clamp(r12 * r23, 1e-5, 0.9999);
    vec3 r123_sqrt = sqrt(r123);
    vec3 rs = (t121 * t121) * r23 / (1.0 - r123);
    vec3 i = r12 + rs;
    vec3 cm = (rs - t121) * r123_sqrt;
    i += cm * (2.0 * gltf_iridescence_sensitivity(opd, phi));
    cm *= r123_sqrt;
    i += cm * (2.0 * gltf_iridescence_sensitivity(2.0 * opd, 2.0 * phi));
    return cos2_theta2 < 0.0 ? vec3(1.0) : max(i, vec3(0.0));
}

void gltf_iridescence_parts(vec3 c, float m, float x, vec3 film_f0, vec3 fd, float v_dot_h, out float fd_max,
                            out vec3 fresnel)
{
    float thickness = mix(u_gltf_pbr_iridescence_thickness_minimum, u_gltf_pbr_iridescence_thickness_maximum,
                          u_gltf_pbr_iridescence_thickness_mix);
    float w = u_gltf_pbr_iridescence;
    float ior = u_gltf_pbr_iridescence_ior;
    vec3 fd_i = mix(fd, gltf_iridescence_fresnel(1.0, ior, film_f0, thickness, v_dot_h), w);
    vec3 fm_i = mix(c + (1.0 - c) * x, gltf_iridescence_fresnel(1.0, ior, c, thickness, v_dot_h), w);
    fd_max = max(fd_i.r, max(fd_i.g, fd_i.b));
    fresnel = fd_i * (1.0 - m) + fm_i * m;
}
#endif
