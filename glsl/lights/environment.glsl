// lights/environment.glsl -- an environment light: radiance from an equirectangular map (docs/design.md section 13;
// glphong/lights/environment.py; the twin's functions have the same names in glphong/twin/environment.py).
//
// environment_irradiance(x, n, j) = E(n) = integral L(w) (n.w)^+ dw [W/m^2], one of:
//   ENVIRONMENT_IRRADIANCE_MAP: environment_cube, the bilinear blend of a cube map of E at its texel centres
//     (6 R^2 texels, R = u_environment_resolution[j]), each computed from the map's exact per-texel integrals;
//   ENVIRONMENT_IRRADIANCE_SH: environment_sh(n, 1, j), the spherical harmonics up to ENVIRONMENT_SH_ORDER convolved
//     with the clamped cosine (order 2: Ramamoorthi and Hanrahan 2001).
// environment_lobe(x, n, r, q, j) = environment_sh(r, q, j) = sum_l lambda_l(q) sum_m L_lm Y_lm(F r), the lobe
//   max(r.w, 0)^q convolved with the map (Funk-Hecke), lambda_l(q) = 2 pi c_l(q), c_l(q) = integral_0^1 t^q P_l(t) dt:
//   c_0 = 1/(q+1), c_1 = 1/(q+2), c_l = c_(l-2) (q - l + 2)/(q + l + 1); F (u_environment_frame) turns world
//   directions into the map's.  It is not clipped at the surface's horizon (the method error map shows where that
//   matters); Y_lm by the normalised Legendre recurrence times Re/Im (x + i y)^m.
// environment_sample(x, n, j, k, wi, E): texel k of the map averaged onto s x 2s lat-long texels
//   (s = u_environment_samples[j]): wi its moment's direction M_k/|M_k| (world), E = Lbar_k |M_k|, so that
//   (n.wi) E = Lbar_k n.M_k, the texel's exact irradiance where it is wholly above the horizon.
// Key defines read here: ENVIRONMENT_IRRADIANCE_MAP, ENVIRONMENT_IRRADIANCE_SH, ENVIRONMENT_SH, ENVIRONMENT_SH_ORDER,
//   ENVIRONMENT_USES_SAMPLE, and the array sizes ENVIRONMENT_MAP_TEXELS, ENVIRONMENT_SH_COEFFICIENTS,
//   ENVIRONMENT_SAMPLE_TEXELS (a program declares only what its terms read).

#if defined(ENVIRONMENT_IRRADIANCE_MAP)
vec3 environment_cube(vec3 n, int j)
{
    vec3 a = abs(n);
    int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    float major = axis == 0 ? n.x : (axis == 1 ? n.y : n.z);
    vec2 st = (axis == 0 ? n.yz : (axis == 1 ? n.zx : n.xy)) / abs(major);
    int face = 2 * axis + (major < 0.0 ? 1 : 0);
    int size = int(u_environment_resolution[j]);
    float R = float(size);
    vec2 u = clamp((st + 1.0) * (0.5 * R) - 0.5, 0.0, R - 1.0);
    ivec2 i0 = min(ivec2(floor(u)), ivec2(size - 2));
    vec2 fr = u - vec2(i0);
    int base = j * ENVIRONMENT_MAP_TEXELS + face * size * size + i0.y * size + i0.x;
    vec3 low = u_environment_irradiance[base] + (u_environment_irradiance[base + 1] - u_environment_irradiance[base]) * fr.x;
    vec3 high = u_environment_irradiance[base + size]
                + (u_environment_irradiance[base + size + 1] - u_environment_irradiance[base + size]) * fr.x;
    return low + (high - low) * fr.y;
}
#endif

#if defined(ENVIRONMENT_SH)
vec3 environment_sh(vec3 r, float q, int j)
{
    vec3 d = vec3(dot(u_environment_frame[3 * j], r), dot(u_environment_frame[3 * j + 1], r),
                  dot(u_environment_frame[3 * j + 2], r));
    float lambda[ENVIRONMENT_SH_ORDER + 2];
    lambda[0] = 1.0 / (q + 1.0);
    lambda[1] = 1.0 / (q + 2.0);
    for (int l = 2; l <= ENVIRONMENT_SH_ORDER; ++l) {
        lambda[l] = lambda[l - 2] * (q - float(l) + 2.0) / (q + float(l) + 1.0);
    }
    int base = j * ENVIRONMENT_SH_COEFFICIENTS;
    vec3 sum = vec3(0.0);
    float pmm = 0.28209479177387814;
    float cm = 1.0;
    float sm = 0.0;
    for (int m = 0; m <= ENVIRONMENT_SH_ORDER; ++m) {
        if (m > 0) {
            pmm *= sqrt((2.0 * float(m) + 1.0) / (2.0 * float(m)));
            float c = d.x * cm - d.y * sm;
            sm = d.x * sm + d.y * cm;
            cm = c;
        }
        float pa = 0.0;
        float pb = pmm;
        for (int l = m; l <= ENVIRONMENT_SH_ORDER; ++l) {
            float p = pmm;
            if (l > m) {
                float fl = float(l);
                float fm = float(m);
                float a = sqrt((4.0 * fl * fl - 1.0) / (fl * fl - fm * fm));
                float b = sqrt(((fl - 1.0) * (fl - 1.0) - fm * fm) / (4.0 * (fl - 1.0) * (fl - 1.0) - 1.0));
                p = a * (d.z * pb - b * pa);
                pa = pb;
                pb = p;
            }
            int i = base + l * l + l;
            vec3 term = m == 0 ? p * u_environment_sh[i]
                               : (1.41421356237310 * p) * (cm * u_environment_sh[i + m] + sm * u_environment_sh[i - m]);
            sum += (6.28318530717959 * lambda[l]) * term;
        }
    }
    return sum;
}
#endif

vec3 environment_irradiance(vec3 x, vec3 n, int j)
{
#if defined(ENVIRONMENT_IRRADIANCE_MAP)
    return environment_cube(n, j);
#elif defined(ENVIRONMENT_IRRADIANCE_SH)
    return environment_sh(n, 1.0, j);
#else
    return vec3(0.0);
#endif
}

vec3 environment_lobe(vec3 x, vec3 n, vec3 r, float q, int j)
{
#if defined(ENVIRONMENT_SH)
    return environment_sh(r, q, j);
#else
    return vec3(0.0);
#endif
}

bool environment_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)
{
#if defined(ENVIRONMENT_USES_SAMPLE)
    int s = int(u_environment_samples[j]);
    int i = j * ENVIRONMENT_SAMPLE_TEXELS + min(k, ENVIRONMENT_SAMPLE_TEXELS - 1);
    wi = u_environment_sample_direction[i];
    irradiance = u_environment_sample_irradiance[i];
    return k < 2 * s * s;
#else
    wi = vec3(0.0, 0.0, 1.0);
    irradiance = vec3(0.0);
    return false;
#endif
}
