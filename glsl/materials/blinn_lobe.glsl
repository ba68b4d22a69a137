// materials/blinn_lobe.glsl -- the model 'blinn_lobe': the Blinn-Torrance lobe (DESIGN E5), in the
// chord form of DESIGN section 3.
//
// blinn_delta(n, wi, wo, out delta) -> valid
//   h = (l + v) / |l + v| by scaled normalisation;  delta = |h - n|^2 / 2  (= 1 - n.h).
//   valid is false (and the lobe 0) where n.v <= 0 or |l + v| <= BLINN_HALF_FLOOR:
//   there h is undefined (l = -v) or dominated by rounding.
// blinn_lobe(n, wi, wo, q) -> max(n.h, 0)^q, 0 where blinn_delta is not valid.
//   n, wi (= l), wo (= v): unit vectors pointing away from the surface; q >= 0.  Dimensionless.
//   NAIVE (the textbook formulation, for the stability report only): pow(max(dot(n, normalize(l + v)), 0), q).
// blinn_lobe_response(f, wi, wo, n_dot_l) -> u_blinn_lobe_ks blinn_lobe(n, wi, wo, u_blinn_lobe_q)   [1/sr]
// Uniforms (declared by glphong from the model's params): u_blinn_lobe_ks, u_blinn_lobe_q.
// Key defines read here: NAIVE.

const float BLINN_HALF_FLOOR = 9.5367431640625e-07;  // 2^-20

bool blinn_delta(vec3 n, vec3 wi, vec3 wo, out float delta)
{
    vec3 h;
    float h_len;
    delta = 2.0;
    if (!(dot(n, wo) > 0.0) || !safe_normalize(wi + wo, h, h_len) || !(h_len > BLINN_HALF_FLOOR)) {
        return false;
    }
    vec3 e = h - n;
    delta = 0.5 * dot(e, e);
    return true;
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
    if (!blinn_delta(n, wi, wo, delta)) {
        return 0.0;
    }
    return lobe_from_delta(delta, q);
}
#endif

vec3 blinn_lobe_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    return u_blinn_lobe_ks * blinn_lobe(f.n, wi, wo, u_blinn_lobe_q);
}
