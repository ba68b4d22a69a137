// naive.glsl -- the textbook float32 formulation, kept only for the stability report.
//
//   safe_normalize(x) : x_hat = normalize(x), len = length(x), always "valid"
//   point_irradiance  : E = I / (d * d)                                 (forms d^2)
//   phong_lobe        : pow(max(dot(v, 2 (n.l) n - l), 0), q)
//   blinn_lobe        : pow(max(dot(n, normalize(l + v)), 0), q)
// It defines the names of the stable chunks it replaces (common, lights, lobe, phong, blinn), so
// shade.glsl runs on it unchanged: the report then shows, case by case, what DESIGN section 3's
// formulation fixes (overshoot above the peak at high q, NaN from pow(0, 0) or zero vectors,
// d^2 underflow and overflow).  It has no numpy twin: it is judged against the mpmath oracle.

bool safe_normalize(vec3 x, out vec3 x_hat, out float len)
{
    x_hat = normalize(x);
    len = length(x);
    return true;
}

vec3 point_irradiance(vec3 intensity, float d)
{
    return intensity / (d * d);
}

float phong_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    return pow(max(dot(wo, 2.0 * dot(n, wi) * n - wi), 0.0), q);
}

float blinn_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    return pow(max(dot(n, normalize(wi + wo)), 0.0), q);
}
