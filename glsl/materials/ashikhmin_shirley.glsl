// materials/ashikhmin_shirley.glsl -- the model 'ashikhmin_shirley': the anisotropic Phong BRDF of
// Ashikhmin and Shirley 2000 (JGT 5(2)), specular and coupled diffuse in one term (docs/design.md section 9).
//
// f_r = f_s + f_d   [1/sr], local frame (t, b, n), h = (l + v) / |l + v|:
//   f_s = sqrt((nu + 1)(nv + 1)) / (8 pi) (n.h)^e F(v.h) / ((v.h) max(n.l, n.v))
//   e   = (nu (h.t)^2 + nv (h.b)^2) / (1 - (n.h)^2),   F(u) = rho_s + (1 - rho_s)(1 - u)^5  (Schlick, u = v.h = l.h)
//   f_d = 28 rho_d / (23 pi) (1 - rho_s) (1 - (1 - n.l/2)^5) (1 - (1 - n.v/2)^5)
// rho_d, rho_s: rgb in [0, 1]; nu, nv: exponents in [0, 1e6] (a larger nu: a narrower lobe along t).
//
// Stable formulation (docs/design.md section 3), branchless (selects only):
// ashikhmin_shirley_norm(nu, nv) -> sqrt((nu + 1)(nv + 1)) / (8 pi)
// ashikhmin_shirley_exponent(h_t, h_b, nu, nv) -> e
//   1 - (n.h)^2 = (h.t)^2 + (h.b)^2, so e = (nu a^2 + nv c^2) / (a^2 + c^2), a = h.t / m, c = h.b / m,
//   m = max(|h.t|, |h.b|): a weighted mean of nu and nv, never 0/0 as n.h rounds to 1, no underflow of
//   the squares (the denominator is in [1, 2]) and no cancellation (positive terms only: e is good to a
//   few ulp relative; a mix(nu, nv, w) would carry nu eps absolute, a 2% error of (n.h)^e at nu = 1e6);
//   at h = n exactly (m = 0) e = (nu + nv)/2 (any value: (n.h)^e = 1 there).
// ashikhmin_shirley_diffuse_factor(c) -> 1 - (1 - c/2)^5 = y (1 + m + m^2 + m^3 + m^4),  y = c/2, m = 1 - y
//   (positive terms only: no cancellation at grazing c; c clamped to [0, 1]).
// ashikhmin_shirley_diffuse(n_dot_l, n_dot_v, rho_d, rho_s) -> f_d (n.l), as separate factors (each <= 1
//   after the constant, so a partial product never underflows where the result is representable).
// ashikhmin_shirley_specular(f, wi, wo, n_dot_l, n_dot_v, rho_s, nu, nv) -> f_s (n.l)
//   h by scaled normalisation; 0 where |l + v| <= ASHIKHMIN_SHIRLEY_HALF_FLOOR (2^-20: h is rounding
//   noise there, as blinn_lobe's floor); (n.h)^e = lobe_from_delta(delta, e), delta = |h - n|^2 / 2
//   (chord form, e up to 1e6 at the peak); v.h = |l + v| / 2 (exact for unit l, v; good to eps absolute,
//   where dot(v, h) of vectors unit only to eps carries (|v|^2 - |l|^2) / (2 |l + v|), as large as v.h
//   itself at |l + v| ~ 1e-4), so 1 / (v.h) <= 2^21; n.l / max(n.l, n.v) in (0, 1] (n.l > 0 here);
//   F = fresnel_schlick(rho_s, v.h) (fresnel.glsl: the cosine clamped to [0, 1], so a v.h that rounds
//   above 1 gives rho_s).
//   The largest value: sqrt((1e6 + 1)^2)/(8 pi) 2^21 ~ 8e10, finite.
//   NAIVE (the textbook formulation, for the stability report only): pow(n.h, e) with e from
//   1 - (n.h)^2 by subtraction, v.h = dot(v, h), 1 - pow(1 - c/2, 5).
// ashikhmin_shirley_response(f, wi, wo, n_dot_l) -> (f_s + f_d) (n.l)    [1/sr];  0 where n.v <= 0.
// Uniforms (declared by glphong from the model's params): u_ashikhmin_shirley_rho_d,
// u_ashikhmin_shirley_rho_s, u_ashikhmin_shirley_nu, u_ashikhmin_shirley_nv.
// Library chunks: lobe.glsl (lobe_from_delta), fresnel.glsl (fresnel_schlick).
// Key defines read here: NAIVE, (HAS_TANGENT through the frame f.t, f.b).

const float ASHIKHMIN_SHIRLEY_HALF_FLOOR = 9.5367431640625e-07;  // 2^-20
const float ASHIKHMIN_SHIRLEY_INV_8PI = 0.039788735772973836;     // 1 / (8 pi)
const float ASHIKHMIN_SHIRLEY_DIFFUSE_NORM = 0.387507687528093;   // 28 / (23 pi)

float ashikhmin_shirley_norm(float nu, float nv)
{
    return sqrt((nu + 1.0) * (nv + 1.0)) * ASHIKHMIN_SHIRLEY_INV_8PI;
}

float ashikhmin_shirley_exponent(float h_t, float h_b, float nu, float nv)
{
    float m = max(abs(h_t), abs(h_b));
    float safe = m > 0.0 ? m : 1.0;
    float a = h_t / safe;
    float c = h_b / safe;
    float a2 = a * a;
    float c2 = c * c;
    return m > 0.0 ? (nu * a2 + nv * c2) / (a2 + c2) : 0.5 * (nu + nv);
}

#if NAIVE
float ashikhmin_shirley_diffuse_factor(float c)
{
    return 1.0 - pow(1.0 - 0.5 * c, 5.0);
}
#else
float ashikhmin_shirley_diffuse_factor(float c)
{
    float y = 0.5 * clamp(c, 0.0, 1.0);
    float m = 1.0 - y;
    return y * (1.0 + m * (1.0 + m * (1.0 + m * (1.0 + m))));
}
#endif

vec3 ashikhmin_shirley_diffuse(float n_dot_l, float n_dot_v, vec3 rho_d, vec3 rho_s)
{
    vec3 k = ASHIKHMIN_SHIRLEY_DIFFUSE_NORM * (rho_d * (vec3(1.0) - rho_s));
    return ((k * n_dot_l) * ashikhmin_shirley_diffuse_factor(n_dot_l)) * ashikhmin_shirley_diffuse_factor(n_dot_v);
}

#if NAIVE
vec3 ashikhmin_shirley_specular(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l, float n_dot_v, vec3 rho_s,
                                float nu, float nv)
{
    vec3 h = normalize(wi + wo);
    float n_dot_h = dot(f.n, h);
    float h_t = dot(h, f.t);
    float h_b = dot(h, f.b);
    float e = (nu * h_t * h_t + nv * h_b * h_b) / (1.0 - n_dot_h * n_dot_h);
    float v_dot_h = dot(wo, h);
    vec3 F = rho_s + (vec3(1.0) - rho_s) * pow(1.0 - v_dot_h, 5.0);
    return ashikhmin_shirley_norm(nu, nv) * pow(max(n_dot_h, 0.0), e) * F * n_dot_l
           / (v_dot_h * max(n_dot_l, n_dot_v));
}
#else
vec3 ashikhmin_shirley_specular(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l, float n_dot_v, vec3 rho_s,
                                float nu, float nv)
{
    vec3 h;
    float h_len;
    bool valid = safe_normalize(wi + wo, h, h_len);
    valid = valid && h_len > ASHIKHMIN_SHIRLEY_HALF_FLOOR;
    vec3 d = h - f.n;
    float delta = 0.5 * dot(d, d);
    float e = ashikhmin_shirley_exponent(dot(h, f.t), dot(h, f.b), nu, nv);
    float lobe = lobe_from_delta(delta, e);
    float v_dot_h = 0.5 * max(h_len, ASHIKHMIN_SHIRLEY_HALF_FLOOR);
    float ratio = n_dot_l / max(n_dot_l, n_dot_v);
    float scale = ashikhmin_shirley_norm(nu, nv) * (ratio / v_dot_h);
    vec3 F = fresnel_schlick(rho_s, v_dot_h);
    return valid ? F * (scale * lobe) : vec3(0.0);
}
#endif

vec3 ashikhmin_shirley_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    float n_dot_v = dot(f.n, wo);
    vec3 value = ashikhmin_shirley_diffuse(n_dot_l, n_dot_v, u_ashikhmin_shirley_rho_d, u_ashikhmin_shirley_rho_s)
               + ashikhmin_shirley_specular(f, wi, wo, n_dot_l, n_dot_v, u_ashikhmin_shirley_rho_s,
                                            u_ashikhmin_shirley_nu, u_ashikhmin_shirley_nv);
    return n_dot_v > 0.0 ? value : vec3(0.0);
}
