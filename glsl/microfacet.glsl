// microfacet.glsl -- the half-vector geometry of the microfacet models and the GGX distribution (library chunk;
// docs/design.md section 9): Cook-Torrance's lobe and glTF's metallic-roughness material.
//
// microfacet_ggx(tan2, a2) -> GGX (Trowbridge-Reitz) D = (a2 r) r / pi [1/sr],  r = 1 + (1 - a2)/(a2 + tan2)
//   = (1 + tan2)/(a2 + tan2): alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2) divided through by (n.h)^4 = 1/(1 + tan2)^2,
//   a sum of positive terms (at the peak a2 + tan2 = a2, 1e-16 at alpha 1e-8); r saturated at FLT_MAX, D at most
//   FLT_MAX, a2/pi where tan2 is Inf; 0 where a2 + tan2 = 0 (alpha 0 at the exact peak: a delta that no point light
//   meets with nonzero measure).  a2 = alpha^2 >= 0.
//
// microfacet_geometry(n, wi, wo, n_dot_l, out n_dot_v, out n_dot_h, out h_dot_l, out tan2) -> valid
//   h by scaled normalisation of l + v; valid is false where l + v does not normalise (l = -v), n.v <= 0 or
//   n.l <= 0.  Stable forms:
//   h.l = |l + v| / 2            (= h.l = h.v for unit l, v; symmetric, no cancellation of dot(h, l) as l -> -v)
//   n.h = (n.l + n.v) / |l + v|  (positive, relatively accurate also for grazing h)
//   tan2 = delta (2 - delta) / (n.h)^2,  delta = |h - n|^2 / 2   (= (1 - (n.h)^2) / (n.h)^2 from the chord:
//          no 1 - (n.h)^2 cancellation at the peak; Inf, not NaN, where (n.h)^2 underflows).
//   Where not valid: n_dot_v = n_dot_h = h_dot_l = 1, tan2 = 0 (every later factor finite).
// Unit vectors pointing away from the surface; dimensionless results.

bool microfacet_geometry(vec3 n, vec3 wi, vec3 wo, float n_dot_l, out float n_dot_v, out float n_dot_h,
                            out float h_dot_l, out float tan2)
{
    vec3 h;
    float h_len;
    bool ok = safe_normalize(wi + wo, h, h_len);
    float nv = dot(n, wo);
    bool valid = ok && nv > 0.0 && n_dot_l > 0.0;
    float len = valid ? h_len : 1.0;
    float nh = valid ? (n_dot_l + nv) / len : 1.0;
    vec3 e = h - n;
    float delta = 0.5 * dot(e, e);
    float sin2 = max(delta * (2.0 - delta), 0.0);
    n_dot_v = valid ? nv : 1.0;
    n_dot_h = nh;
    h_dot_l = 0.5 * len;
    tan2 = valid ? sin2 / (nh * nh) : 0.0;
    return valid;
}

const float MICROFACET_INV_PI = 0.3183098861837907;

float microfacet_ggx(float tan2, float a2)
{
    float s = a2 + tan2;
    float r = 1.0 + (1.0 - a2) / s;
    float value = (a2 * r) * (min(r, FLT_MAX) * MICROFACET_INV_PI);
    return s > 0.0 ? min(value, FLT_MAX) : 0.0;
}
