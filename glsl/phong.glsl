// phong.glsl -- the Phong lobe (DESIGN E4), in the chord form of DESIGN section 3.
//
// phong_delta(n, wi, wo) -> delta = |r - v|^2 / 2,   r = 2 (n.l) n - l
//   equals 1 - v.r for unit vectors, without the cancellation of 1 - dot(v, r) near the peak.
// phong_lobe(n, wi, wo, q) -> max(v.r, 0)^q = lobe_from_delta(phong_delta(n, wi, wo), q)
//   n, wi (= l), wo (= v): unit vectors pointing away from the surface; q >= 0.  Dimensionless.

float phong_delta(vec3 n, vec3 wi, vec3 wo)
{
    vec3 r = 2.0 * dot(n, wi) * n - wi;
    vec3 e = r - wo;
    return 0.5 * dot(e, e);
}

float phong_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    return lobe_from_delta(phong_delta(n, wi, wo), q);
}
