// area.glsl -- a uniform convex polygon seen from a point: the lecture's continuous version over an area light
// (library chunk; docs/design.md section 13; twin: glphong/twin/area.py, function by function).
//
// A polygon is held relative to the shading point x: vertices p[i] = v_i - x and edges e[i] = p[i+1] - p[i],
// the edges given exactly (from the host, in float64 rounded once), so an edge's direction does not cancel in
// p[i+1] - p[i] when the light is small and far (section 13, conditioning).  The polygon's vertices run
// counter-clockwise seen from x (x in front of its emitting side).
//
// area_angle(y, x) -> atan2(y, x) in [0, pi] for y >= 0: Cephes' polynomial (angle.glsl), 3 ulp.
// area_clip(p, e, count, c) -> count: the part with c.y >= 0 (a plane through x), Sutherland-Hodgman; a kept
//   piece of an edge keeps its exact direction (e t), only the new edge along the plane is a difference.
// area_polygon_cosine(p, e, count, n) -> integral over the polygon of (n.w) dw  [sr]   (Lambert's edge formula)
//   = -(1/2) sum_i Theta_i (n . m_i),  Theta_i = atan2(|p_i x e_i|, p_i.(p_i + e_i)),  m_i = unit(p_i x e_i);
//   exact for a polygon wholly above the horizon of n (clip it by n first): E = L times it.
// area_solid_angle(p, e, count) -> Omega [sr]: the fan's triangles by Van Oosterom and Strackee,
//   tan(Omega_t / 2) = |a.(b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|), where that is below 2 sr; else
//   Girard's 2 pi - sum of the exterior angles between consecutive edge planes m_i (the fan's denominators cancel
//   for a polygon covering much of the hemisphere: 1e-4 relative measured under a 2e4 m square at 1 m).
// area_edge_powers(a, e, w, q) -> S = sum_{k in K} integral_0^Theta (w.u(t))^k dt along the edge's great circle,
//   K = {0, 2, ..., q - 1} for odd q, {1, 3, ..., q - 1} for even q, by the recurrence (s = w.u, s' = ds/dt,
//   R^2 = 1 - (w.m)^2 = |w x m|^2):  E_0 = Theta,  E_1 = [-s']_0^Theta,
//   E_k = ((k - 1) R^2 E_{k-2} - [s^{k-1} s']_0^Theta) / k  (forward: each step scales the error by < 1),
//   stopped once the tail bound Theta R^k / (1 - R^2) is below 2^-24 of the sum.
// area_polygon_lobe(p, e, count, w, q) -> integral over the polygon of (w.u)^q du  [sr], integer q >= 0, the
//   polygon clipped to w.u >= 0 (Arvo 1995, irradiance tensors):
//   = ((q even) Omega - sum_i (w . m_i) S_i) / (q + 1).       q = 1 is Lambert's edge formula.
// area_clipped_cosine(p, e, count, n) = area_polygon_cosine(clip(P, n), n)              E(n) / L, exact
// area_clipped_lobe(p, e, count, n, r, q) = area_polygon_lobe(clip(clip(P, n), r), r, q)  the lobe / L, exact
// area_triangle_sample(a, e1, e2, m, k, out point, out weight): cell k of the m^2 congruent sub-triangles of the
//   triangle (a, a + e1, a + e2): its centroid and area [m^2] (the midpoint rule of the sampled method).
// Key defines read here: none.

#define AREA_MAX_VERTICES 10

float area_angle(float y, float x)
{
    return x >= 0.0 ? atan2_first_quadrant(y, x) : 3.14159265358979 - atan2_first_quadrant(y, -x);
}

int area_clip(inout vec3 p[AREA_MAX_VERTICES], inout vec3 e[AREA_MAX_VERTICES], int count, vec3 c)
{
    float d[AREA_MAX_VERTICES];
    for (int i = 0; i < AREA_MAX_VERTICES; ++i)
        d[i] = i < count ? dot(c, p[i]) : 0.0;
    vec3 q[AREA_MAX_VERTICES];
    vec3 f[AREA_MAX_VERTICES];
    int m = 0;
    int open = -1;
    for (int i = 0; i < AREA_MAX_VERTICES; ++i) {
        if (i >= count) break;
        int next = i + 1 < count ? i + 1 : 0;
        bool a_in = d[i] >= 0.0;
        bool b_in = d[next] >= 0.0;
        float t = a_in == b_in ? 0.0 : d[i] / (d[i] - d[next]);
        if (a_in) {
            q[m] = p[i];
            f[m] = b_in ? e[i] : e[i] * t;
            m = min(m + 1, AREA_MAX_VERTICES - 1);
        }
        if (a_in && !b_in) {
            q[m] = p[i] + e[i] * t;
            open = m;
            m = min(m + 1, AREA_MAX_VERTICES - 1);
        }
        if (!a_in && b_in) {
            q[m] = p[i] + e[i] * t;
            f[m] = e[i] * (1.0 - t);
            m = min(m + 1, AREA_MAX_VERTICES - 1);
        }
    }
    for (int i = 0; i < AREA_MAX_VERTICES; ++i) {
        if (i >= m) break;
        p[i] = q[i];
        e[i] = f[i];
    }
    if (open >= 0)
        e[open] = q[open + 1 < m ? open + 1 : 0] - q[open];
    return m;
}

float area_polygon_cosine(vec3 p[AREA_MAX_VERTICES], vec3 e[AREA_MAX_VERTICES], int count, vec3 n)
{
    float sum = 0.0;
    for (int i = 0; i < AREA_MAX_VERTICES; ++i) {
        if (i >= count) break;
        vec3 g = cross(p[i], e[i]);
        float s = length(g);
        float theta = area_angle(s, dot(p[i], p[i] + e[i]));
        sum += s > 0.0 ? theta * (dot(n, g) / s) : 0.0;
    }
    return count >= 3 ? max(-0.5 * sum, 0.0) : 0.0;
}

float area_solid_angle(vec3 p[AREA_MAX_VERTICES], vec3 e[AREA_MAX_VERTICES], int count)
{
    // Girard: 2 pi less the exterior angles between consecutive edge planes (well conditioned for a large polygon,
    // whose fan triangles' denominators cancel), else the fan by Van Oosterom and Strackee (a small one)
    vec3 first = vec3(0.0);
    vec3 previous = vec3(0.0);
    int edges = 0;
    float turn = 0.0;
    for (int i = 0; i < AREA_MAX_VERTICES; ++i) {
        if (i >= count) break;
        vec3 g = cross(p[i], e[i]);
        float s = length(g);
        if (s > 0.0) {
            vec3 m = g / s;
            turn += edges > 0 ? area_angle(length(cross(previous, m)), dot(previous, m)) : 0.0;
            first = edges > 0 ? first : m;
            previous = m;
            edges += 1;
        }
    }
    turn += area_angle(length(cross(previous, first)), dot(previous, first));
    float girard = edges >= 3 ? max(6.28318530717959 - turn, 0.0) : 0.0;
    float omega = 0.0;
    for (int i = 1; i < AREA_MAX_VERTICES - 1; ++i) {
        if (i + 1 >= count) break;
        vec3 a = p[0];
        vec3 b = p[i];
        vec3 c = p[i + 1];
        float la = length(a);
        float lb = length(b);
        float lc = length(c);
        float y = abs(dot(a, cross(b, c)));
        float x = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
        omega += 2.0 * area_angle(y, x);
    }
    return omega < 2.0 ? omega : girard;
}

float area_edge_powers(vec3 a, vec3 e, vec3 w, float q)
{
    vec3 g = cross(a, e);
    float s = length(g);
    if (!(s > 0.0))
        return 0.0;
    vec3 m = g / s;
    vec3 ua = normalize(a);
    vec3 b = a + e;
    vec3 ub = normalize(b);
    float theta = area_angle(s, dot(a, b));
    float sa = dot(w, ua);                     // s(0)
    float da = dot(w, cross(m, ua));           // s'(0)
    float sb = dot(w, ub);                     // s(Theta)
    float db = dot(w, cross(m, ub));           // s'(Theta)
    vec3 across = cross(w, m);
    float r2 = dot(across, across);             // R^2 = 1 - (w.m)^2 = |w x m|^2, which does not cancel where w ~ m
    int qi = int(q);
    bool even = qi - 2 * (qi / 2) == 0;
    // E_0 = Theta and E_1 = [-s']_0^Theta = da - db; the sum runs over k of q's other parity, below q
    float ek = even ? da - db : theta;
    float pa = even ? sa * sa : sa;            // s(0)^(k+1), what the step from E_k to E_{k+2} reads
    float pb = even ? sb * sb : sb;            // s(Theta)^(k+1)
    float sum = 0.0;
    // |E_k| <= Theta R^k, so the terms from k on add at most Theta R^k / (1 - R^2): stop where that is below
    // 2^-24 of the sum (llvmpipe also ends a loop after 65535 iterations, which LOBE_MAX_Q keeps clear of)
    float rk = even ? sqrt(r2) : 1.0;
    float tail = theta / max(1.0 - r2, 1e-30);
    for (int k = even ? 1 : 0; k < qi; k += 2) {
        if (rk * tail < 5.9604645e-8 * abs(sum))
            break;
        rk *= r2;
        sum += ek;
        float kn = float(k + 2);
        ek = ((kn - 1.0) * r2 * ek - (pb * db - pa * da)) / kn;
        pa *= sa * sa;
        pb *= sb * sb;
    }
    return sum;
}

float area_polygon_lobe(vec3 p[AREA_MAX_VERTICES], vec3 e[AREA_MAX_VERTICES], int count, vec3 w, float q)
{
    if (count < 3)
        return 0.0;
    float sum = 0.0;
    for (int i = 0; i < AREA_MAX_VERTICES; ++i) {
        if (i >= count) break;
        vec3 g = cross(p[i], e[i]);
        float s = length(g);
        sum += s > 0.0 ? (dot(w, g) / s) * area_edge_powers(p[i], e[i], w, q) : 0.0;
    }
    int qi = int(q);
    float omega = qi - 2 * (qi / 2) == 0 ? area_solid_angle(p, e, count) : 0.0;
    return max((omega - sum) / (q + 1.0), 0.0);
}

float area_clipped_cosine(vec3 p[AREA_MAX_VERTICES], vec3 e[AREA_MAX_VERTICES], int count, vec3 n)
{
    count = area_clip(p, e, count, n);
    return area_polygon_cosine(p, e, count, n);
}

float area_clipped_lobe(vec3 p[AREA_MAX_VERTICES], vec3 e[AREA_MAX_VERTICES], int count, vec3 n, vec3 r, float q)
{
    count = area_clip(p, e, count, n);
    count = area_clip(p, e, count, r);
    return area_polygon_lobe(p, e, count, r, q);
}

void area_triangle_sample(vec3 a, vec3 e1, vec3 e2, int m, int k, out vec3 point, out float weight)
{
    int i = int(floor(sqrt(float(k))));                   // the row: k in [i^2, (i + 1)^2)
    i = (i + 1) * (i + 1) <= k ? i + 1 : (i * i > k ? i - 1 : i);
    int jj = k - i * i;
    int b = jj / 2;
    bool up = jj - 2 * b == 0;
    float fa = up ? float(i - b) + 0.333333333 : float(i - 1 - b) + 0.666666667;
    float fb = up ? float(b) + 0.333333333 : float(b) + 0.666666667;
    point = a + e1 * (fa / float(m)) + e2 * (fb / float(m));
    weight = 0.5 * length(cross(e1, e2)) / float(m * m);
}
