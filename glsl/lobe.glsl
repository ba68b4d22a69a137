// lobe.glsl -- stable evaluation of a cosine-power lobe (docs/design.md section 3).
//
// log_one_minus_series(delta) -> ln(1 - delta) for 0 <= delta < 1/2
//   -2 artanh(sigma),  sigma = delta / (2 - delta)  (2 sigma formed directly, so that delta just above
//   FLT_MIN does not pass through a subnormal sigma),
//   artanh(sigma) = sum_{k=0..7} sigma^(2k+1) / (2k+1)   (sigma <= 1/3: truncation < 2^-27)
//   Accurate to a few ulp relative even for delta ~ 1e-30, where log(1.0 - delta) would return 0.
// log_one_minus(delta) -> ln(1 - delta),  0 <= delta < 1
//   delta < 1/2:  log_one_minus_series(delta);  delta >= 1/2: log(1 - delta)   (1 - delta is exact there, Sterbenz)
//
// lobe_from_delta(delta, q) -> (1 - delta)^q = cos^q
//   delta = 1 - cos, the distance from the lobe peak (0 at the peak);  q >= 0 the exponent.
//   q == 0: 1 (0^0 := 1);  delta >= 1 (cos <= 0): 0, the max(cos, 0) clamp;
//   else exp(max(q ln(1 - delta), -104)).  Never NaN, never above 1.
//   LOBE_TAIL_ZERO (numerics='auto', where every exponent of the program is at least LOBE_TAIL_Q = 151,
//   docs/design.md section 3): delta >= 1/2 gives 0 and the log branch is left out.  The same bits: there
//   q ln(1 - delta) <= 151 (ln(1/2) + 2^-21) < -104, so the full form returns exp(-104) ~ 6.8e-46, which
//   float32 rounds (or flushes) to 0; below 1/2 both evaluate log_one_minus_series.
//
// The two cosine-power lobes of the lecture, shared by every model built on them (phong_lobe,
// blinn_lobe, the normalised lobes).  n, wi (= l), wo (= v): unit vectors pointing away from the
// surface; q >= 0.  Dimensionless.  NAIVE (the textbook formulation, for the stability report only)
// replaces each lobe by its pow() form.
// phong_delta(n, wi, wo) -> delta = |r - v|^2 / 2,   r = 2 (n.l) n - l
//   equals 1 - v.r for unit vectors, without the cancellation of 1 - dot(v, r) near the peak.
// phong_lobe(n, wi, wo, q) -> max(v.r, 0)^q = lobe_from_delta(phong_delta(n, wi, wo), q)
//   NAIVE: pow(max(dot(v, r), 0), q).
// blinn_delta(n, wi, wo, out delta) -> valid
//   h = (l + v) / |l + v| by scaled normalisation;  delta = |h - n|^2 / 2  (= 1 - n.h).
//   valid is false (delta 2, the lobe 0) where n.v <= 0 or |l + v| <= BLINN_HALF_FLOOR = 2^-20:
//   there h is undefined (l = -v) or dominated by rounding.
// blinn_lobe(n, wi, wo, q) -> max(n.h, 0)^q, 0 where blinn_delta is not valid.
//   NAIVE: pow(max(dot(n, normalize(l + v)), 0), q).
// half_cosine(wi, wo) -> h.l, 0 where l + v does not normalise (the cosine of a half-vector Fresnel factor).
// Key defines read here: NAIVE (phong_lobe, blinn_lobe), LOBE_TAIL_ZERO (lobe_from_delta).

float log_one_minus_series(float delta)
{
    float two_sigma = (2.0 * delta) / (2.0 - delta);
    float t = 0.25 * (two_sigma * two_sigma);
    float series = 1.0 + t * (1.0 / 3.0 + t * (1.0 / 5.0 + t * (1.0 / 7.0 + t * (1.0 / 9.0
                 + t * (1.0 / 11.0 + t * (1.0 / 13.0 + t * (1.0 / 15.0)))))));
    return -two_sigma * series;
}

float log_one_minus(float delta)
{
    return delta < 0.5 ? log_one_minus_series(delta) : log(1.0 - delta);
}

#if LOBE_TAIL_ZERO
float lobe_from_delta(float delta, float q)
{
    float lobe = exp(max(q * log_one_minus_series(delta < 0.5 ? delta : 0.0), -104.0));
    return q == 0.0 ? 1.0 : (delta < 0.5 ? lobe : 0.0);
}
#else
float lobe_from_delta(float delta, float q)
{
    float lobe = exp(max(q * log_one_minus(delta < 1.0 ? delta : 0.0), -104.0));
    return q == 0.0 ? 1.0 : (delta < 1.0 ? lobe : 0.0);
}
#endif

float phong_delta(vec3 n, vec3 wi, vec3 wo)
{
    vec3 r = 2.0 * dot(n, wi) * n - wi;
    vec3 e = r - wo;
    return 0.5 * dot(e, e);
}

#if NAIVE
float phong_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    return pow(max(dot(wo, 2.0 * dot(n, wi) * n - wi), 0.0), q);
}
#else
float phong_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    return lobe_from_delta(phong_delta(n, wi, wo), q);
}
#endif

const float BLINN_HALF_FLOOR = 9.5367431640625e-07;  // 2^-20

bool blinn_delta(vec3 n, vec3 wi, vec3 wo, out float delta)
{
    vec3 h;
    float h_len;
    bool defined = safe_normalize(wi + wo, h, h_len);
    bool valid = (dot(n, wo) > 0.0) && defined && (h_len > BLINN_HALF_FLOOR);
    vec3 e = h - n;
    delta = valid ? 0.5 * dot(e, e) : 2.0;
    return valid;
}

#if NAIVE
float blinn_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    return pow(max(dot(n, normalize(wi + wo)), 0.0), q);
}
#else
float blinn_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    float delta;
    bool valid = blinn_delta(n, wi, wo, delta);
    float lobe = lobe_from_delta(delta, q);
    return valid ? lobe : 0.0;
}
#endif

float half_cosine(vec3 wi, vec3 wo)
{
    vec3 h;
    float h_len;
    bool defined = safe_normalize(wi + wo, h, h_len);
    return defined ? dot(h, wi) : 0.0;
}
