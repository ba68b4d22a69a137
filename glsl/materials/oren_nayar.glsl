// materials/oren_nayar.glsl -- the model 'oren_nayar': Oren and Nayar's rough diffuse reflection
// (Oren and Nayar 1994, "Generalization of Lambert's reflectance model", SIGGRAPH 94; docs/design.md section 9),
// in a stable float32 formulation: no acos, no tan, no 1 - cos by subtraction.
//
// f_r [1/sr], with s2 = sigma^2 (sigma in radians), theta_i, theta_o the polar angles of l and v,
// alpha = max(theta_i, theta_o), beta = min(theta_i, theta_o), c = cos(phi_o - phi_i):
//   full (OREN_NAYAR_FORM == 0, the default):
//     rho/pi (C1 + c C2 tan(beta) + (1 - |c|) C3 tan((alpha + beta)/2))
//       + 0.17 rho^2/pi s2/(s2 + 0.13) (1 - c (2 beta/pi)^2)                     (inter-reflection)
//     C1 = 1 - 0.5 s2/(s2 + 0.33);  C2 = 0.45 s2/(s2 + 0.09) sin(alpha)                   (c >= 0)
//                                   C2 = 0.45 s2/(s2 + 0.09) (sin(alpha) - (2 beta/pi)^3)  (c < 0)
//     C3 = 0.125 s2/(s2 + 0.09) (4 alpha beta/pi^2)^2
//   qualitative (OREN_NAYAR_FORM == 1):
//     rho/pi (A + B max(0, c) sin(alpha) tan(beta)),  A = 1 - 0.5 s2/(s2 + 0.33),  B = 0.45 s2/(s2 + 0.09)
// sigma = 0 is Lambert's rho/pi exactly (C1 = A = 1, every other factor exactly 0).
// Valid ranges: rho in [0, 1] (dimensionless), sigma in [0, pi/2] rad; the response is evaluated
// where n.l > 0 (the light loop's gate) and is exactly 0 where n.v <= 0 (a select).
//
// The stable formulation (every factor bounded: no NaN or Inf from valid input):
// oren_nayar_tangential(n, w, out dir) -> sin(theta) = |w - (n.w) n|, the tangential part's length by
//   safe_normalize (clamped to 1), dir its unit direction (0 where it vanishes).  cos(theta) = n.w.
//   Near the normal acos(n.w) resolves no angle below 3.5e-4 rad in float32 (n.w = 1 - eps); the
//   tangential part keeps sin(theta) to a few eps absolute.
// oren_nayar_cos_phi(dir_i, dir_o, out one_minus_c, out one_minus_abs_c) -> c = clamp(dir_i . dir_o, -1, 1),
//   with 1 - c = |dir_i - dir_o|^2 / 2 and 1 + c = |dir_i + dir_o|^2 / 2 as chords (1 - |c| is the
//   smaller): no 1 - cos by subtraction where l and v are aligned or opposed in azimuth.  It matters
//   where both graze: the response is ~ n.l there, while (1 - |c|) C3 tan((alpha + beta)/2) (n.l)
//   is ~ (1 - |c|).  c = 0 (1 - c = 1 - |c| = 1) where either direction vanishes (l = n or v = n):
//   there beta = 0, which removes every c term, so the value is the limit whatever c is.
// oren_nayar_tan_beta(cos_i, sin_i, cos_o, sin_o, out sin_alpha, out cos_alpha) -> tan(beta) (n.l):
//   sin_i where theta_i <= theta_o (tan(theta_i) cos(theta_i)), else sin_o (n.l / n.v) with
//   n.l / n.v <= 1 there: at most 1, though tan(beta) itself diverges where l and v both graze.
//   tan((alpha + beta)/2) (n.l) = (sin_i + sin_o) (n.l / (n.l + n.v)) (half-angle identity): at most 2.
//   So the response f_r (n.l) stays bounded where f_r itself diverges (both grazing, c > 0: the
//   paper's model is meant for theta < pi/2 and diverges as 1/(n.l) there).
// The polar angles come from atan2_first_quadrant (angle.glsl: Cephes' atanf, 3 ulp; GLSL's own atan
//   errs 2e-5 relative on llvmpipe, which the full form's cancelling sums (C1 against c C2 tan(beta),
//   c < 0) turned into 1e-4 relative error of the response).
// The angles enter through g = 1 - 2 theta/pi = (2/pi) atan2_first_quadrant(cos(theta), sin(theta)),
//   relatively accurate at grazing, where the textbook sin(alpha) - (2 beta/pi)^3 and
//   1 - (2 beta/pi)^2 cancel (g_b = max(g_i, g_o) is beta's, g_a = min(g_i, g_o) alpha's):
//   sin(alpha) - (2 beta/pi)^3 = g_b (3 - 3 g_b + g_b^2) - cos(alpha)^2 / (1 + sin(alpha)),
//   1 - c (2 beta/pi)^2 = (1 - c) + c g_b (2 - g_b)   (1 - c from the chord),
//   4 alpha beta/pi^2 = (1 - g_a)(1 - g_b).
// oren_nayar_full(...) -> vec2(single scattering f_r (n.l) pi/rho, inter-reflection f_r (n.l) pi/rho^2).
// oren_nayar_qualitative(...) -> f_r (n.l) pi/rho.
// oren_nayar_response(f, wi, wo, n_dot_l) -> u_oren_nayar_rho (k.x / pi) + u_oren_nayar_rho^2 (k.y / pi)
//   [1/sr]: f_r (n.l); the inter-reflection term is quadratic in rho.
// Uniforms (declared by glphong from the model's params): u_oren_nayar_rho, u_oren_nayar_sigma.
// Key defines read here: OREN_NAYAR_FORM (0 full, 1 qualitative; 0 where undefined, e.g. in a probe).

#ifndef OREN_NAYAR_FORM
#define OREN_NAYAR_FORM 0
#endif

const float OREN_NAYAR_INV_PI = 0.3183098861837907;
const float OREN_NAYAR_TWO_OVER_PI = 0.6366197723675814;

float oren_nayar_tangential(vec3 n, vec3 w, out vec3 dir)
{
    float len;
    safe_normalize(w - dot(n, w) * n, dir, len);
    return min(len, 1.0);
}

float oren_nayar_cos_phi(vec3 dir_i, vec3 dir_o, out float one_minus_c, out float one_minus_abs_c)
{
    bool defined = dot(dir_i, dir_i) > 0.0 && dot(dir_o, dir_o) > 0.0;
    vec3 d = dir_i - dir_o;
    vec3 s = dir_i + dir_o;
    float minus = 0.5 * dot(d, d);  // 1 - c, accurate where c -> 1 (retro-reflection)
    float plus = 0.5 * dot(s, s);   // 1 + c, accurate where c -> -1 (forward scattering)
    one_minus_c = defined ? minus : 1.0;
    one_minus_abs_c = defined ? min(minus, plus) : 1.0;
    return defined ? clamp(dot(dir_i, dir_o), -1.0, 1.0) : 0.0;
}

float oren_nayar_tan_beta(float cos_i, float sin_i, float cos_o, float sin_o, out float sin_alpha,
                          out float cos_alpha)
{
    bool light_is_beta = sin_i * cos_o <= sin_o * cos_i;  // tan(theta_i) <= tan(theta_o)
    sin_alpha = light_is_beta ? sin_o : sin_i;
    cos_alpha = light_is_beta ? cos_o : cos_i;
    return light_is_beta ? sin_i : sin_o * (cos_i / max(cos_o, cos_i));
}

vec2 oren_nayar_full(float cos_i, float sin_i, float cos_o, float sin_o, float c, float one_minus_c,
                     float one_minus_abs_c, float s2)
{
    float sin_alpha, cos_alpha;
    float tan_beta = oren_nayar_tan_beta(cos_i, sin_i, cos_o, sin_o, sin_alpha, cos_alpha);
    float tan_half = (sin_i + sin_o) * (cos_i / (cos_i + cos_o));
    float g_i = OREN_NAYAR_TWO_OVER_PI * atan2_first_quadrant(cos_i, sin_i);
    float g_o = OREN_NAYAR_TWO_OVER_PI * atan2_first_quadrant(cos_o, sin_o);
    float g_b = max(g_i, g_o);
    float g_a = min(g_i, g_o);
    float k = s2 / (s2 + 0.09);
    float c1 = 1.0 - 0.5 * s2 / (s2 + 0.33);
    float drop = g_b * (3.0 - 3.0 * g_b + g_b * g_b) - cos_alpha * cos_alpha / (1.0 + sin_alpha);
    float c2 = 0.45 * k * (c >= 0.0 ? sin_alpha : drop);
    float ab = (1.0 - g_a) * (1.0 - g_b);
    float c3 = 0.125 * k * (ab * ab);
    float single = c1 * cos_i + c * c2 * tan_beta + one_minus_abs_c * c3 * tan_half;
    float inter = 0.17 * s2 / (s2 + 0.13) * (one_minus_c + c * (g_b * (2.0 - g_b))) * cos_i;
    return vec2(single, inter);
}

float oren_nayar_qualitative(float cos_i, float sin_i, float cos_o, float sin_o, float c, float s2)
{
    float sin_alpha, cos_alpha;
    float tan_beta = oren_nayar_tan_beta(cos_i, sin_i, cos_o, sin_o, sin_alpha, cos_alpha);
    float a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    float b = 0.45 * s2 / (s2 + 0.09);
    return a * cos_i + b * max(c, 0.0) * sin_alpha * tan_beta;
}

vec3 oren_nayar_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    float n_dot_v = dot(f.n, wo);
    vec3 dir_i, dir_o;
    float sin_i = oren_nayar_tangential(f.n, wi, dir_i);
    float sin_o = oren_nayar_tangential(f.n, wo, dir_o);
    // below the surface: a finite stand-in (grazing view), selected away at the end
    sin_o = n_dot_v > 0.0 ? sin_o : 1.0;
    float cos_o = max(n_dot_v, 0.0);
    float one_minus_c, one_minus_abs_c;
    float c = oren_nayar_cos_phi(dir_i, dir_o, one_minus_c, one_minus_abs_c);
    float s2 = u_oren_nayar_sigma * u_oren_nayar_sigma;
#if OREN_NAYAR_FORM == 1
    vec2 k = vec2(oren_nayar_qualitative(n_dot_l, sin_i, cos_o, sin_o, c, s2), 0.0);
#else
    vec2 k = oren_nayar_full(n_dot_l, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c, s2);
#endif
    vec3 value = u_oren_nayar_rho * (k.x * OREN_NAYAR_INV_PI)
                 + u_oren_nayar_rho * u_oren_nayar_rho * (k.y * OREN_NAYAR_INV_PI);
    return n_dot_v > 0.0 ? value : vec3(0.0);
}
