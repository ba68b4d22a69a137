// lights/rect.glsl -- a one-sided uniform parallelogram light (docs/design.md section 13; glphong/lights/area.py).
//
// Corners c +- u/2 +- v/2, emitting radiance L_j [W/(m^2 sr)] toward the side u x v points to.
// rect_polygon(x, j, p, e) -> count: the corners relative to x, counter-clockwise seen from the front
//   (c - u/2 - v/2, then + u, + v, - u) with the edges u, v, -u, -v exactly; 0 where x is not in front,
//   (x - c).(u x v) <= 0.
// rect_irradiance(x, n, j) = L_j area_clipped_cosine(P, n)          E(n), exact (Lambert's edge formula)
// rect_lobe(x, n, r, q, j) = L_j area_clipped_lobe(P, n, r, q) Arvo, exact for integer q
// rect_sample(x, n, j, k, wi, E): cell k = (a, b) of m x m (m = u_rect_samples[j]), its centre y:
//   wi = (y - x)/d,  E = L_j cos_l (A / m^2) / d^2,  cos_l = -wi.(u x v)/A,  A = |u x v|  (the midpoint rule);
//   valid where k < m^2, the direction normalises and cos_l > 0.
// Key defines read here: none (RECT_MAX_SAMPLES bounds the generated loop).

int rect_polygon(vec3 x, int j, out vec3 p[AREA_MAX_VERTICES], out vec3 e[AREA_MAX_VERTICES])
{
    vec3 u = u_rect_u[j];
    vec3 v = u_rect_v[j];
    vec3 a = (u_rect_center[j] - x) - 0.5 * u - 0.5 * v;
    p[0] = a;
    p[1] = a + u;
    p[2] = a + u + v;
    p[3] = a + v;
    e[0] = u;
    e[1] = v;
    e[2] = -u;
    e[3] = -v;
    return dot(x - u_rect_center[j], cross(u, v)) > 0.0 ? 4 : 0;
}

vec3 rect_irradiance(vec3 x, vec3 n, int j)
{
    vec3 p[AREA_MAX_VERTICES];
    vec3 e[AREA_MAX_VERTICES];
    int count = rect_polygon(x, j, p, e);
    return u_rect_radiance[j] * area_clipped_cosine(p, e, count, n);
}

vec3 rect_lobe(vec3 x, vec3 n, vec3 r, float q, int j)
{
    vec3 p[AREA_MAX_VERTICES];
    vec3 e[AREA_MAX_VERTICES];
    int count = rect_polygon(x, j, p, e);
    return u_rect_radiance[j] * area_clipped_lobe(p, e, count, n, r, q);
}

bool rect_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)
{
    int m = int(u_rect_samples[j]);
    int a = k / m;
    int b = k - a * m;
    vec3 u = u_rect_u[j];
    vec3 v = u_rect_v[j];
    vec3 y = (u_rect_center[j] - x) + u * ((float(a) + 0.5) / float(m) - 0.5) + v * ((float(b) + 0.5) / float(m) - 0.5);
    float d;
    bool valid = safe_normalize(y, wi, d);
    vec3 front = cross(u, v);
    float area = length(front);
    float cos_l = -dot(front, wi) / area;
    irradiance = u_rect_radiance[j] * (((cos_l * (area / float(m * m))) / d) / d);
    return valid && k < m * m && cos_l > 0.0;
}
