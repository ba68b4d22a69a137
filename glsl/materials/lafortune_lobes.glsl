// materials/lafortune_lobes.glsl -- the model 'lafortune_lobes': the generalised cosine lobes of
// Lafortune, Foo, Torrance and Greenberg 1997 (docs/design.md section 9), in a generalised chord form.
//
// f_r = sum_{i=1..LAFORTUNE_LOBES_COUNT} rho_i max(x_i, 0)^(n_i)   [1/sr],
//   x_i = Cx_i l_x v_x + Cy_i l_y v_y + Cz_i l_z v_z,  components in the local frame (t, b, n):
//   l_x = l.t, l_y = l.b, l_z = l.n (likewise v).  rho_i >= 0 (rgb, 1/sr), C_i finite (Cx, Cy, Cz),
//   0 <= n_i <= 1e6; n_i = 0 gives the constant lobe rho_i (the 0^0 := 1 convention of lobe.glsl).
//   C = (-1, -1, 1): x = v.r, the Phong lobe; C = (c, c, c), c > 0: retro-reflection c^n (l.v)^n;
//   -Cx = -Cy > Cz: off-specular; Cx != Cy: anisotropic.  Symmetric in l and v (reciprocal).
//
// The generalised chord form (instead of pow(x, n), whose relative error is ~ n eps |C| / x and which
// cannot resolve the peak of a high exponent):  with m = max_i |C_i| and c^ = C / m (|c^_i| <= 1),
//   x = m |c^ o l| (w.v),  w = (c^ o l) / |c^ o l|            (o: the componentwise product)
//   |c^ o l|^2 = 1 - u,    u = sum_i (1 - |c^_i|)(1 + |c^_i|) l_i^2 / |l|^2   in [0, 1]   (|l| = |v| = 1)
//   w.v = 1 - delta,       delta = |w - v|^2 / 2              (the chord: no cancellation at the peak)
//   x^n = exp(n (ln m + ln(1 - u) / 2 + ln(1 - delta)))
// every logarithm accurate to a few ulp relative (log_one_minus of lobe.glsl; ln m by lafortune_log).
// For C = (-1, -1, 1) this is the chord form of phong_lobe of lobe.glsl (m = 1, u = 0 exactly), so the lobe is
// exact at its peak for any n; for |Cx| = |Cy| = |Cz| (Phong-type, retro-reflective) u = 0 exactly too.
// Accuracy (float32, eps = 2^-24), relative, near the peak:
//   eps (16 + 4 lambda + 6 s sqrt(2 n lambda)) + 4 eps n (|ln m| + |ln(1 - u)| / 2) + 8 eps n sqrt(u / (1 - u))
//   lambda = -n ln(1 - delta), s = 1 / sqrt(1 - u) (the conditioning of w); the last term is the lobe's
//   own sensitivity to the direction of l when |C_i| differ (an angle error of eps moves u), the second
//   the rounding of the magnitude's logarithms: both 0 for |Cx| = |Cy| = |Cz|, so Phong-type and
//   retro-reflective lobes keep the chord form's accuracy up to n = 1e6 (and beyond); for general C
//   the bound grows like 8 eps n sqrt(u): valid range (relative error <~ 1e-3) n sqrt(u) <~ 2e3, e.g.
//   n <~ 5e3 where the |C_i| differ by 10 %, n <~ 1.5e4 where they differ by 1 % (LafortuneLobes.band is
//   this estimate; measured errors are 3 to 8 times smaller).  The textbook pow(x, n) is worse
//   everywhere: ~ n eps |C| / x, up to 17 % at n = 1e6 near the peak.
// The exponent is clamped to [-104, 88]: lobes below e^-104 are 0 (flushed), above e^88 ~ 1.65e38 they
// saturate there (|C| > 1 with a large n): rho * lobe is then at most FLT_MAX or +Inf, never NaN
// (a zero channel of rho stays 0: the lobe is finite).
//
// lafortune_local(f, d) -> (d.t, d.b, d.n), the local-frame components of a direction (not renormalised:
//   the chord form depends on |v| - 1 only as lambda (|v| - 1), and a float32 renormalisation would cost
//   more, by rounding v's direction, than it gains; l's length drops out: w is normalised, u divides by |l|^2).
// lafortune_log(m) -> ln m for m > 0: log_one_minus(1 - m) on [0.5, 1], -log_one_minus((m - 1)/m) on
//   (1, 2] (both differences exact, Sterbenz), log(m) elsewhere (GLSL's log is only 2^-21 absolute in
//   [0.5, 2], too coarse for n ln m with n = 1e6).
// lafortune_lobe(l, v, c, q) -> max(c.(l o v), 0)^q, l and v local; 1 for q = 0; 0 where x <= 0, where
//   C = 0 or where c^ o l = 0.  Dimensionless (above 1 where |C| > 1).  Never NaN.
//   NAIVE (the textbook formulation, for the stability report only): pow(max(dot(c * l, v), 0), q).
// lafortune_lobes_response(f, wi, wo, n_dot_l) -> (sum_i u_lafortune_lobes_lobe<i>_rho lafortune_lobe(l, v,
//   u_lafortune_lobes_lobe<i>_c, u_lafortune_lobes_lobe<i>_n)) n.l   [1/sr] = f_r (n.l).  No n.v gate:
//   the paper's formula as written (a view below the surface is only seen on one-sided materials).
// Uniforms (declared by glphong from the model's params): u_lafortune_lobes_lobe<k>_rho (rgb),
// u_lafortune_lobes_lobe<k>_c (rgb holding Cx, Cy, Cz), u_lafortune_lobes_lobe<k>_n, k = 1..4; those of
// lobes above LAFORTUNE_LOBES_COUNT are not read (inactive, dropped by the compiler).
// Key defines read here: NAIVE, LAFORTUNE_LOBES_COUNT (1..4, the number of lobes).

#if LAFORTUNE_LOBES_COUNT < 1 || LAFORTUNE_LOBES_COUNT > 4
#error "LAFORTUNE_LOBES_COUNT must be 1 to 4 (LAFORTUNE_MAX_LOBES)"
#endif

const float LAFORTUNE_EXP_MIN = -104.0;  // exp(-104) ~ 6.8e-46: flushed to 0, as lobe_from_delta
const float LAFORTUNE_EXP_MAX = 88.0;    // exp(88) ~ 1.65e38 < FLT_MAX: the lobe saturates there

vec3 lafortune_local(ShadingFrame f, vec3 d)
{
    return vec3(dot(d, f.t), dot(d, f.b), dot(d, f.n));
}

float lafortune_log(float m)
{
    float below = log_one_minus(1.0 - m);
    float above = -log_one_minus((m - 1.0) / m);
    float direct = log(m);
    return m < 0.5 ? direct : (m <= 1.0 ? below : (m <= 2.0 ? above : direct));
}

#if NAIVE
float lafortune_lobe(vec3 l, vec3 v, vec3 c, float q)
{
    return pow(max(dot(c * l, v), 0.0), q);
}
#else
float lafortune_lobe(vec3 l, vec3 v, vec3 c, float q)
{
    float m = max(max(abs(c.x), abs(c.y)), abs(c.z));
    bool c_ok = m > 0.0;
    float m_safe = c_ok ? m : 1.0;
    vec3 c_hat = c / m_safe;
    vec3 a = abs(c_hat);
    vec3 k = (1.0 - a) * (1.0 + a);
    vec3 l2 = l * l;
    float u = dot(k, l2) / max(l2.x + l2.y + l2.z, 1e-30);
    vec3 w;
    float w_len;
    bool w_ok = safe_normalize(c_hat * l, w, w_len);
    vec3 e = w - v;
    float delta = 0.5 * dot(e, e);
    bool ok = c_ok && w_ok && u < 1.0 && delta < 1.0;
    float log_x = (lafortune_log(m_safe) + 0.5 * log_one_minus(ok ? u : 0.0)) + log_one_minus(ok ? delta : 0.0);
    float value = ok ? exp(clamp(q * log_x, LAFORTUNE_EXP_MIN, LAFORTUNE_EXP_MAX)) : 0.0;
    return q == 0.0 ? 1.0 : value;
}
#endif

vec3 lafortune_lobes_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    vec3 l = lafortune_local(f, wi);
    vec3 v = lafortune_local(f, wo);
    vec3 fr = u_lafortune_lobes_lobe1_rho * lafortune_lobe(l, v, u_lafortune_lobes_lobe1_c, u_lafortune_lobes_lobe1_n);
#if LAFORTUNE_LOBES_COUNT >= 2
    fr += u_lafortune_lobes_lobe2_rho * lafortune_lobe(l, v, u_lafortune_lobes_lobe2_c, u_lafortune_lobes_lobe2_n);
#endif
#if LAFORTUNE_LOBES_COUNT >= 3
    fr += u_lafortune_lobes_lobe3_rho * lafortune_lobe(l, v, u_lafortune_lobes_lobe3_c, u_lafortune_lobes_lobe3_n);
#endif
#if LAFORTUNE_LOBES_COUNT >= 4
    fr += u_lafortune_lobes_lobe4_rho * lafortune_lobe(l, v, u_lafortune_lobes_lobe4_c, u_lafortune_lobes_lobe4_n);
#endif
    return fr * n_dot_l;
}
