// materials/measured_brdf.glsl -- the model 'measured_brdf': an isotropic BRDF measured (or tabulated)
// in the MERL layout (Matusik, Pfister, Brand and McMillan 2003, "A data-driven reflectance model",
// SIGGRAPH 2003; Rusinkiewicz 1998 for the angles; docs/design.md section 9).
//
// f_r [1/sr] (rgb) = the table at the bin of (theta_h, theta_d, phi_d):
//   h = (l + v)/|l + v|,  theta_h = angle(n, h),  theta_d = angle(h, l),
//   phi_d = the azimuth of l about h from u = -normalize(n - (n.h) h), folded into [0, pi) by
//   reciprocity (+ pi where negative; pi itself is 0, the same azimuth after the fold, where the
//   reference reader clamps it into the last bin); where h = n, u is the tangent of Duff et al.'s basis around h
//   (frame_from_tangent's fallback; +x for h = +z, where glphong.merl.half_diff takes the tangent).
// measured_brdf_coordinates(n, wi, wo) -> the continuous bin coordinates
//   x_h = 90 sqrt(theta_h / (pi/2)),  x_d = 90 theta_d / (pi/2),  x_p = 180 phi_d / pi.
// measured_brdf_nearest(x) -> the bin floor(x) clamped to the table (MEASURED_BRDF_LOOKUP == 0, the
//   default: the MERL reference reader's lookup, no interpolation).
// measured_brdf_trilinear(x) -> trilinear between the samples at x_h = i, x_d = j + 1/2, x_p = k + 1/2
//   (the directions glphong.merl.tabulate evaluates a model at), clamped in theta_h and theta_d,
//   periodic in phi_d (period pi: 180 bins) (MEASURED_BRDF_LOOKUP == 1).
// measured_brdf_response(f, wi, wo, n_dot_l) -> f_r (n.l) [1/sr]; 0 where n.v <= 0 (a select: the
//   table covers the upper hemisphere only).
//
// Stable float32 formulation: every angle is atan2_first_quadrant(part across, part along) (angle.glsl),
//   never acos of a dot product: near the peak acos resolves no angle below 3.5e-4 rad in float32,
//   which is 1.3 bins of x_h there (the bins are finest at theta_h = 0).  theta_d is half the angle
//   between l and v, atan(|l - v| / |l + v|), and the azimuth comes from d = l - v (l's part across
//   h, twice) along u and h x u: swapping l and v negates d exactly, so the folded coordinates are
//   bit-identical (reciprocal in float32 too), at any scale.  No branch; indices clamped, so no fetch
//   leaves the table.  NAIVE (the textbook formulation, for the stability report only): acos of the dots.
// Valid range: the table's entries finite and >= 0 (unmeasured cells are 0: MeasuredBRDF replaces
//   the file's negative markers when it reads a table).
// Uniforms (declared by glphong from the model's table): u_measured_brdf_table, a sampler3D holding
//   (90, 90, 180) x 3 float32, texel (k, j, i) = table[i][j][k].
// Key defines read here: MEASURED_BRDF_LOOKUP (0 nearest, 1 trilinear; 0 where undefined), NAIVE.

#ifndef MEASURED_BRDF_LOOKUP
#define MEASURED_BRDF_LOOKUP 0
#endif

const ivec3 MEASURED_BRDF_LAST = ivec3(89, 89, 179);  // the table's last bin per axis (90, 90, 180 bins)
const float MEASURED_BRDF_PI = 3.14159265358979;

vec3 measured_brdf_coordinates(vec3 n, vec3 wi, vec3 wo)
{
    vec3 h, u, fallback, unused;
    float len, sin_h;
    safe_normalize(wi + wo, h, len);
    float cos_h = dot(n, h);
    bool tilted = safe_normalize(cos_h * h - n, u, sin_h);
    frame_from_tangent(h, vec4(0.0), fallback, unused);
    u = tilted ? u : fallback;
    vec3 d = wi - wo;                                  // 2 (l - (h.l) h): l's part across h, twice
    float y = dot(d, cross(h, u));
    float x = dot(d, u);
#if NAIVE
    float theta_h = acos(clamp(cos_h, -1.0, 1.0));
    float theta_d = acos(clamp(dot(h, wi), -1.0, 1.0));
    float phi = atan(y, x);
    float phi_d = phi < 0.0 ? phi + MEASURED_BRDF_PI : phi;
#else
    float theta_h = atan2_first_quadrant(min(sin_h, 1.0), max(cos_h, 0.0));
    float theta_d = atan2_first_quadrant(length(d), len);  // half the angle between l and v: |l - v|, |l + v|
    // atan2(y, x) folded into [0, pi): (y, x) -> (-y, -x) where y < 0, or y = 0 and x < 0 (pi is 0)
    bool flip = y < 0.0 || (y == 0.0 && x < 0.0);
    float ys = flip ? -y : y;
    float xs = flip ? -x : x;
    float a = atan2_first_quadrant(ys, abs(xs));
    float phi_d = xs < 0.0 ? MEASURED_BRDF_PI - a : a;
#endif
    return vec3(90.0 * sqrt(theta_h * (2.0 / MEASURED_BRDF_PI)), theta_d * (180.0 / MEASURED_BRDF_PI),
                phi_d * (180.0 / MEASURED_BRDF_PI));
}

vec3 measured_brdf_fetch(ivec3 i)
{
    return texelFetch(u_measured_brdf_table, i.zyx, 0).rgb;
}

vec3 measured_brdf_nearest(vec3 x)
{
    return measured_brdf_fetch(clamp(ivec3(floor(x)), ivec3(0), MEASURED_BRDF_LAST));
}

vec3 measured_brdf_trilinear(vec3 x)
{
    vec3 a = x - vec3(0.0, 0.5, 0.5);
    vec3 base = floor(a);
    vec3 w = a - base;
    ivec3 i = ivec3(base);
    ivec3 lo = ivec3(clamp(i.xy, ivec2(0), MEASURED_BRDF_LAST.xy), (i.z + 180) % 180);
    ivec3 hi = ivec3(clamp(i.xy + 1, ivec2(0), MEASURED_BRDF_LAST.xy), (i.z + 181) % 180);
    vec3 c00 = mix(measured_brdf_fetch(ivec3(lo.x, lo.y, lo.z)), measured_brdf_fetch(ivec3(lo.x, lo.y, hi.z)), w.z);
    vec3 c01 = mix(measured_brdf_fetch(ivec3(lo.x, hi.y, lo.z)), measured_brdf_fetch(ivec3(lo.x, hi.y, hi.z)), w.z);
    vec3 c10 = mix(measured_brdf_fetch(ivec3(hi.x, lo.y, lo.z)), measured_brdf_fetch(ivec3(hi.x, lo.y, hi.z)), w.z);
    vec3 c11 = mix(measured_brdf_fetch(ivec3(hi.x, hi.y, lo.z)), measured_brdf_fetch(ivec3(hi.x, hi.y, hi.z)), w.z);
    return mix(mix(c00, c01, w.y), mix(c10, c11, w.y), w.x);
}

vec3 measured_brdf_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    vec3 x = measured_brdf_coordinates(f.n, wi, wo);
#if MEASURED_BRDF_LOOKUP == 1
    vec3 value = measured_brdf_trilinear(x);
#else
    vec3 value = measured_brdf_nearest(x);
#endif
    return dot(f.n, wo) > 0.0 ? value * n_dot_l : vec3(0.0);
}
