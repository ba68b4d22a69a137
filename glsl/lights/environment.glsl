// lights/environment.glsl -- an environment light: radiance from an equirectangular map (docs/design.md section 13;
// glphong/lights/environment.py; the twin's functions have the same names in glphong/twin/environment.py).
//
// environment_irradiance(x, n, j) = E(n) = integral L(w) (n.w)^+ dw [W/m^2], one of:
//   ENVIRONMENT_IRRADIANCE_MAP: environment_cube, the bilinear blend of a cube map of E at its texels
//     (6 R^2 texels, R = u_environment_resolution[j], at -1 + 2 i/(R - 1) of each face, its edges included: the
//     blend is continuous across the faces), each computed from the map's exact per-texel integrals;
//   ENVIRONMENT_IRRADIANCE_SH: environment_sh(n, 1, j), the spherical harmonics up to ENVIRONMENT_SH_ORDER convolved
//     with the clamped cosine (order 2: Ramamoorthi and Hanrahan 2001).
// environment_lobe(x, n, r, q, j) = environment_sh(r, q, j) environment_horizon(q, n.r): the lobe max(r.w, 0)^q
//   convolved with the map (Funk-Hecke), sum_l lambda_l(q) sum_m L_lm Y_lm(F r), lambda_l(q) = 2 pi c_l(q),
//   c_l(q) = integral_0^1 t^q P_l(t) dt: c_0 = 1/(q+1), c_1 = 1/(q+2), c_l = c_(l-2) (q - l + 2)/(q + l + 1);
//   F (u_environment_frame) turns world directions into the map's; Y_lm by the normalised Legendre recurrence times
//   Re/Im (x + i y)^m; times the part of the lobe above the surface's horizon under a uniform sky.
// environment_sample(x, n, j, k, wi, E): texel k of the map averaged onto s x 2s lat-long texels
//   (s = u_environment_samples[j]): wi its moment's direction M_k/|M_k| (world), E = Lbar_k |M_k|, so that
//   (n.wi) E = Lbar_k n.M_k, the texel's exact irradiance where it is wholly above the horizon.
// ENVIRONMENT_BRIGHT (a map with texels above its threshold T): the map's excess max(L - T, 0) is integrated apart, as
//   u_environment_bright_count[j] blocks (glphong/twin/environment_bright.py), the cube map and the harmonics holding
//   the residual min(L, T); each block b: direction w_b (its centroid), radius a_b (the flat disc of its solid angle):
//   environment_segment(c, a, f, e): the part of a disc of radius a above a chord at signed distance c from its
//     centre, t = clamp(c/a, -1, 1), u = sqrt(1 - t^2), f = (acos(-t) + t u)/pi (area), e = c f + (2/3) a u^3/pi
//     (cosine-weighted: c wholly above, 0 wholly below);
//   environment_bright_irradiance(n, j) = sum_b max(n.M_bc + |M_bc| (e - c), 0), c = n.w_b, M_bc (c = r, g, b) the
//     exact moments of its excess: n.M_b exactly where its disc is wholly above the horizon;
//   environment_bright_lobe(n, r, q, j) = sum_b P_b max(r.w_b, 0)^q f (the midpoint rule), P_b its power [W/m^2],
//     each block's environment_bright_peak(r, q, i) = P_b max(r.w_b, 0)^q (exp(max(q log x, -104)), 0 for x <= 0).
//   A cap about u_environment_bright_center[j] of angle rho holds every block's disc (u_environment_bright_cap[j] =
//   (cos rho, sin rho, rho), sin rho stored as 2 where rho > pi/2: no horizon leaves such a cap on one side): where the horizon does not cross it Lambert is n.(sum_b M_b) (u_environment_bright_total,
//   3 a light) or 0 and the lobe needs no f; where r is further than rho from it and cos(angle - rho)^q < 1e-8 the
//   lobe is left out (by at most 1e-8 sum_b P_b); each loop runs over the blocks only where it is needed (its bound
//   the light's count, not the define: a constant bound of 8 or less was unrolled, every pixel paying every block).
// Key defines read here: ENVIRONMENT_IRRADIANCE_MAP, ENVIRONMENT_IRRADIANCE_SH, ENVIRONMENT_SH, ENVIRONMENT_SH_ORDER,
//   ENVIRONMENT_USES_SAMPLE, ENVIRONMENT_BRIGHT, ENVIRONMENT_BRIGHT_IRRADIANCE, ENVIRONMENT_BRIGHT_LOBE, and the array
//   sizes ENVIRONMENT_MAP_TEXELS, ENVIRONMENT_SH_COEFFICIENTS, ENVIRONMENT_SAMPLE_TEXELS, ENVIRONMENT_BRIGHT_BLOCKS,
//   ENVIRONMENT_BRIGHT_MOMENTS (a program declares only what its terms read).

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
    vec2 u = clamp((st + 1.0) * (0.5 * (R - 1.0)), 0.0, R - 1.0);
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
                float b = l > m + 1 ? sqrt(((fl - 1.0) * (fl - 1.0) - fm * fm) / (4.0 * (fl - 1.0) * (fl - 1.0) - 1.0))
                                    : 0.0;                  // (0 at l = m + 1, where the ratio is -0/1 or 0/-1)
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

#if defined(ENVIRONMENT_SH)
// environment_horizon(q, c): the part of the lobe max(r.w, 0)^q above the horizon of n, c = n.r >= 0, for a uniform
//   sky: 1 - (q + 1) J / pi, the part below being 2 J with (substituting t = s (1 - v^2) in its integral over t = w.r)
//   J = 2 s^(q+1) integral_0^1 atan2(v sqrt(2 - v^2), c (1 - v^2)) (1 - v^2)^q v dv,  s = sqrt(1 - c^2);
//   24-point Gauss-Legendre on [0, V], V = min(1, 5/sqrt(q + 1)) ((1 - v^2)^q < e^-25 beyond), the weight
//   exp((q + 1) log(s) + q log1p(-v^2)), log(s) = log1p(-c^2)/2; for c < 0 (r below the horizon) the mirror image,
//   the part below of |c|.  Exact for a sky of uniform radiance across the horizon; the convolution
//   times it is the harmonics' lobe clipped at the horizon (docs/design.md section 13 says when it is not exact).
const float ENVIRONMENT_NODES[24] = float[24](
    0.00240638991817832, 0.012635721825063229, 0.030862724408507347, 0.0567922368645668,
    0.0899990051984787, 0.12993790209293365, 0.17595317959785461, 0.22728925943374634,
    0.28310325741767883, 0.3424786627292633, 0.4044405519962311, 0.4679715633392334,
    0.5320284366607666, 0.5955594182014465, 0.6575213670730591, 0.7168967723846436, 0.7727107405662537,
    0.8240468502044678, 0.8700621128082275, 0.9100009799003601, 0.9432077407836914, 0.9691372513771057,
    0.9873642921447754, 0.9975935816764832);
const float ENVIRONMENT_WEIGHTS[24] = float[24](
    0.006170615088194609, 0.014265694655478, 0.022138718515634537, 0.029649293050169945,
    0.03667324036359787, 0.04309508204460144, 0.04880932718515396, 0.053722135722637177,
    0.057752832770347595, 0.06083523482084274, 0.06291873008012772, 0.06396909803152084,
    0.06396909803152084, 0.06291873008012772, 0.06083523482084274, 0.057752832770347595,
    0.053722135722637177, 0.04880932718515396, 0.04309508204460144, 0.03667324036359787,
    0.029649293050169945, 0.022138718515634537, 0.014265694655478, 0.006170615088194609);

float environment_log1p(float x)
{
    float u = 1.0 + x;
    return u == 1.0 ? x : log(u) * x / (u - 1.0);
}

float environment_horizon(float q, float c)
{
    float a = abs(c);
    float log_s = a * a < 1.0 ? 0.5 * environment_log1p(-a * a) : -100.0;   // log(sqrt(1 - c^2)), no cancellation
    float span = min(1.0, 5.0 / sqrt(q + 1.0));
    float sum = 0.0;
    for (int i = 0; i < 24; ++i) {
        float v = span * ENVIRONMENT_NODES[i];
        float u = 1.0 - v * v;
        float weight = exp((q + 1.0) * log_s + q * environment_log1p(-v * v));
        sum += ENVIRONMENT_WEIGHTS[i] * atan2_first_quadrant(v * sqrt(2.0 - v * v), a * u) * weight * v;
    }
    float below = 2.0 * (q + 1.0) / 3.14159265358979 * span * sum;
    return c < 0.0 ? below : 1.0 - below;                   // r below the horizon: the mirror image
}
#endif

#if defined(ENVIRONMENT_BRIGHT)
void environment_segment(float c, float a, out float f, out float e)
{
    float t = clamp(c / a, -1.0, 1.0);
    float u = sqrt(max(1.0 - t * t, 0.0));
    float angle = atan2_first_quadrant(u, abs(t));                  // acos(|t|)
    float above = t >= 0.0 ? 3.14159265358979 - angle : angle;      // acos(-t)
    f = (above + t * u) * 0.318309886183791;
    e = c * f + 0.212206590789194 * a * u * u * u;                  // (2/3)/pi
}
#endif

#if defined(ENVIRONMENT_BRIGHT_IRRADIANCE)
vec3 environment_bright_irradiance(vec3 n, int j)
{
    float c_all = dot(n, u_environment_bright_center[j]);
    float reach = u_environment_bright_cap[j].y;
    bool above = c_all >= reach;                        // every block's disc above the horizon: n.(sum_b M_b)
    int count = above || c_all <= -reach ? 0 : min(int(u_environment_bright_count[j]), ENVIRONMENT_BRIGHT_BLOCKS);
    vec3 sum = above ? vec3(dot(n, u_environment_bright_total[3 * j]), dot(n, u_environment_bright_total[3 * j + 1]),
                            dot(n, u_environment_bright_total[3 * j + 2])) : vec3(0.0);
    for (int k = 0; k < count; ++k) {                   // the horizon crosses the blocks' cap: each block
        int i = j * ENVIRONMENT_BRIGHT_BLOCKS + k;
        float c = dot(n, u_environment_bright_direction[i]);
        float f;
        float e;
        environment_segment(c, u_environment_bright_radius[i], f, e);
        vec3 direct = vec3(dot(n, u_environment_bright_moment[3 * i]), dot(n, u_environment_bright_moment[3 * i + 1]),
                           dot(n, u_environment_bright_moment[3 * i + 2]));
        sum += max(direct + u_environment_bright_length[i] * (e - c), 0.0);
    }
    return sum;
}
#endif

#if defined(ENVIRONMENT_BRIGHT_LOBE)
vec3 environment_bright_peak(vec3 r, float q, int i)                        // P_b max(r.w_b, 0)^q, block i
{
    float x = dot(r, u_environment_bright_direction[i]);
    return u_environment_bright_power[i] * (x > 0.0 ? exp(max(q * log(x), -104.0)) : 0.0);
}

vec3 environment_bright_lobe(vec3 n, vec3 r, float q, int j)
{
    vec3 cap = u_environment_bright_cap[j];
    float c_all = dot(n, u_environment_bright_center[j]);
    float cr = dot(r, u_environment_bright_center[j]);
    float nearest = cr * cap.x + sqrt(max(1.0 - cr * cr, 0.0)) * cap.y;     // cos(angle(r, centre) - rho)
    bool reached = cr >= cap.x || (nearest > 0.0 && q * log(nearest) > -18.420680743952367);   // above 1e-8
    int count = min(int(u_environment_bright_count[j]), ENVIRONMENT_BRIGHT_BLOCKS);
    int plain = reached && c_all >= cap.y ? count : 0;                      // every disc above the horizon: f = 1
    int clipped = reached && c_all < cap.y && c_all > -cap.y ? count : 0;
    vec3 sum = vec3(0.0);
    for (int k = 0; k < plain; ++k) {
        sum += environment_bright_peak(r, q, j * ENVIRONMENT_BRIGHT_BLOCKS + k);
    }
    for (int k = 0; k < clipped; ++k) {
        int i = j * ENVIRONMENT_BRIGHT_BLOCKS + k;
        float f;
        float e;
        environment_segment(dot(n, u_environment_bright_direction[i]), u_environment_bright_radius[i], f, e);
        sum += environment_bright_peak(r, q, i) * f;
    }
    return sum;
}
#endif

vec3 environment_irradiance(vec3 x, vec3 n, int j)
{
#if defined(ENVIRONMENT_IRRADIANCE_MAP)
    vec3 smooth_part = environment_cube(n, j);
#elif defined(ENVIRONMENT_IRRADIANCE_SH)
    vec3 smooth_part = environment_sh(n, 1.0, j);
#else
    vec3 smooth_part = vec3(0.0);
#endif
#if defined(ENVIRONMENT_BRIGHT_IRRADIANCE)
    return smooth_part + environment_bright_irradiance(n, j);
#else
    return smooth_part;
#endif
}

vec3 environment_lobe(vec3 x, vec3 n, vec3 r, float q, int j)
{
#if defined(ENVIRONMENT_SH)
    vec3 smooth_part = environment_sh(r, q, j) * environment_horizon(q, clamp(dot(n, r), -1.0, 1.0));
#else
    vec3 smooth_part = vec3(0.0);
#endif
#if defined(ENVIRONMENT_BRIGHT_LOBE)
    return smooth_part + environment_bright_lobe(n, r, q, j);
#else
    return smooth_part;
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
