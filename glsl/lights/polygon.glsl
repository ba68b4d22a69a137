// lights/polygon.glsl -- a one-sided uniform convex polygon light (docs/design.md section 13; glphong/lights/area.py).
//
// Vertices v_i (i < count_j <= 8), counter-clockwise seen from the side the light emits to (its front normal
// u_polygon_normal[j], made on the host), edges e_i = v_{i+1} - v_i (host, float64 rounded once), radiance L_j.
// polygon_polygon(x, j, p, e) -> count: p_i = v_i - x and the edges; 0 where x is not in front, (x - v_0).N <= 0.
// polygon_irradiance(x, n, j) = L_j area_clipped_cosine(P, n)             E(n), exact
// polygon_lobe(x, n, r, q, j) = L_j area_clipped_lobe(P, n, r, q)    Arvo, exact for integer q
// polygon_sample(x, n, j, k, wi, E): the fan's triangle t = 1 + k / m^2 (v_0, v_t, v_{t+1}), its sub-triangle
//   k mod m^2 of m^2 (area_triangle_sample), centroid y, area A_k:  E = L_j cos_l A_k / d^2, cos_l = -wi.N;
//   valid where t + 1 < count_j, the direction normalises and cos_l > 0.
// Key defines read here: none (POLYGON_MAX_SAMPLES bounds the generated loop).

int polygon_polygon(vec3 x, int j, out vec3 p[AREA_MAX_VERTICES], out vec3 e[AREA_MAX_VERTICES])
{
    int count = int(u_polygon_count[j]);
    for (int i = 0; i < 8; ++i) {
        p[i] = u_polygon_vertex[j * 8 + i] - x;
        e[i] = u_polygon_edge[j * 8 + i];
    }
    return dot(x - u_polygon_vertex[j * 8], u_polygon_normal[j]) > 0.0 ? count : 0;
}

vec3 polygon_irradiance(vec3 x, vec3 n, int j)
{
    vec3 p[AREA_MAX_VERTICES];
    vec3 e[AREA_MAX_VERTICES];
    int count = polygon_polygon(x, j, p, e);
    return u_polygon_radiance[j] * area_clipped_cosine(p, e, count, n);
}

vec3 polygon_lobe(vec3 x, vec3 n, vec3 r, float q, int j)
{
    vec3 p[AREA_MAX_VERTICES];
    vec3 e[AREA_MAX_VERTICES];
    int count = polygon_polygon(x, j, p, e);
    return u_polygon_radiance[j] * area_clipped_lobe(p, e, count, n, r, q);
}

bool polygon_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)
{
    int m = int(u_polygon_samples[j]);
    int t = 1 + k / (m * m);
    int count = int(u_polygon_count[j]);
    int t1 = min(t, 6);
    vec3 a = u_polygon_vertex[j * 8];
    vec3 y;
    float area;
    area_triangle_sample(a - x, u_polygon_vertex[j * 8 + t1] - a, u_polygon_vertex[j * 8 + t1 + 1] - a, m,
                         k - (t - 1) * m * m, y, area);
    float d;
    bool valid = safe_normalize(y, wi, d);
    float cos_l = -dot(u_polygon_normal[j], wi);
    irradiance = u_polygon_radiance[j] * (((cos_l * area) / d) / d);
    return valid && t + 1 < count && cos_l > 0.0;
}
