// materials/phong_lobe.glsl -- the model 'phong_lobe': the Phong lobe (DESIGN E4), in the chord
// form of DESIGN section 3.
//
// phong_delta(n, wi, wo) -> delta = |r - v|^2 / 2,   r = 2 (n.l) n - l
//   equals 1 - v.r for unit vectors, without the cancellation of 1 - dot(v, r) near the peak.
// phong_lobe(n, wi, wo, q) -> max(v.r, 0)^q = lobe_from_delta(phong_delta(n, wi, wo), q)
//   n, wi (= l), wo (= v): unit vectors pointing away from the surface; q >= 0.  Dimensionless.
//   NAIVE (the textbook formulation, for the stability report only): pow(max(dot(v, r), 0), q).
// phong_lobe_response(f, wi, wo, n_dot_l) -> u_phong_lobe_ks phong_lobe(n, wi, wo, u_phong_lobe_q)
//   [1/sr]: the lecture's k_s (v.r)^q, whose BRDF is k_s (v.r)^q / (n.l).
// Uniforms (declared by glphong from the model's params): u_phong_lobe_ks, u_phong_lobe_q.
// Key defines read here: NAIVE.

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

vec3 phong_lobe_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    return u_phong_lobe_ks * phong_lobe(f.n, wi, wo, u_phong_lobe_q);
}
