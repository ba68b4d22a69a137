// shadows.glsl -- shadow-map visibility with a bias derived from the geometry (docs/design.md section 12).
//
// A shadowing light's map holds, per texel, the distance from the light of the nearest caster along the
// texel centre's ray: a cube map (6 faces of SHADOW_MAP_SIZE^2 texels in one float texture, 3 across and 2 up,
// face f at ((f mod 3) N, (f / 3) N), f = 2 a + (s < 0) for the major axis a and its sign s, texel coordinates ((v_b / |v_a| + 1) / 2,
// (v_c / |v_a| + 1) / 2) SHADOW_MAP_SIZE with (b, c) the other two axes in order) for a light at a point, or an
// orthographic map (texel coordinates e1 . (x - o), e2 . (x - o); depth a . (x - o)) for a light at infinity.
//
// shadow_plane_angle(d, c, offset) / shadow_plane_length(c, offset) -> p;  shadow_bias(p, scale) -> B = 2 p + q:
//   p, the largest amount by which the receiver's own plane, along a lookup ray up to `offset` away from the ray
//   to x, can come nearer the light than x (offset an angle [rad] for a cube map: p = d (cos(t) / cos(t + offset)
//   - 1), t the angle between the triangle's normal and the ray, c = |cos(t)|; a length [m] for an orthographic
//   map: p = offset tan(t)), once for the receiver's own triangle and once more for a neighbouring triangle that
//   bends toward the light (a curved or creased receiver), and q = SHADOW_QUANTUM scale, 16 eps of the largest
//   coordinate involved (the stored distance's float32 arithmetic).  A receiver seen edge-on (t + offset >= pi/2)
//   gets B = FLT_MAX: it cannot shadow itself, and is lit.
//   offset = (SHADOW_FILTER_RADIUS + 1/2) sqrt(2) texels: the nearest texel's centre is within half a texel
//   diagonal of x's own ray, and a filter of radius r reaches r texels further along each axis.
// shadow_cube(map, o, texel_angle, x, n) / shadow_ortho(map, o, a, e1, e2, texel_size, x, n) -> V in [0, 1]
//   (n: the triangle's own normal, shadow_face_normal)
//   the fraction of the (2 r + 1)^2 texels around x's own (r = SHADOW_FILTER_RADIUS; 0: the nearest texel alone)
//   whose stored distance is >= d - b (percentage-closer filtering); at a cube face's edge the filter stays on
//   the face (clamped).  texel_angle = 2 / SHADOW_MAP_SIZE, and a cube texel seen along the unit direction v
//   subtends at most texel_angle m, m = max |v_i| (its face's axis component: 1 at a face's centre, 1/sqrt(3) at a
//   corner), since a step ds of the face coordinate turns the ray by m^2 sqrt(1 + t^2) ds <= m ds.
// Units: positions [m]; d, b [m]; texel_angle [rad]; texel_size [m].
// Key defines read here: SHADOW_MAP_SIZE, SHADOW_FILTER_RADIUS.

const float SHADOW_QUANTUM = 9.5367431640625e-07;  // 16 eps: the stored distance's float32 error, relative
// the triangle's own normal at the fragment (mesh_fragment.glsl sets it from the position's derivatives): the slope
// of the plane the map samples, which a smooth shading normal does not give
vec3 shadow_face_normal = vec3(0.0, 0.0, 1.0);

float shadow_plane_angle(float d, float c, float offset)
{
    float s = sqrt(max(1.0 - c * c, 0.0));
    float c_far = c * cos(offset) - s * sin(offset);  // cos(t + offset)
    return c_far > 0.0 ? d * (c / c_far - 1.0) : FLT_MAX;
}

float shadow_plane_length(float c, float offset)
{
    float s = sqrt(max(1.0 - c * c, 0.0));
    return c > 0.0 ? offset * (s / c) : FLT_MAX;
}

float shadow_bias(float plane, float scale)
{
    return min(2.0 * plane + SHADOW_QUANTUM * scale, FLT_MAX);
}

float max_abs(vec3 v)
{
    return max(max(abs(v.x), abs(v.y)), abs(v.z));
}

// the cube face of direction v (ties: x before y before z) and v's texel coordinates on it, in [0, size]
int cube_face(vec3 v, out vec2 st)
{
    vec3 m = abs(v);
    int a = (m.x >= m.y && m.x >= m.z) ? 0 : (m.y >= m.z ? 1 : 2);
    float major = a == 0 ? v.x : (a == 1 ? v.y : v.z);
    vec2 other = a == 0 ? v.yz : (a == 1 ? v.xz : v.xy);
    st = (other / abs(major) + 1.0) * (0.5 * float(SHADOW_MAP_SIZE));
    return 2 * a + (major < 0.0 ? 1 : 0);
}

float shadow_cube(sampler2D map, vec3 origin, float texel_angle, vec3 x, vec3 n)
{
    vec3 v;
    float d;
    if (!safe_normalize(x - origin, v, d)) {
        return 1.0;
    }
    float offset = (float(SHADOW_FILTER_RADIUS) + 0.5) * 1.4142135623730951 * texel_angle * max_abs(v);
    float bias = shadow_bias(shadow_plane_angle(d, abs(dot(n, v)), offset), d + max_abs(x) + max_abs(origin));
    vec2 st;
    int face = cube_face(v, st);
    ivec2 texel = clamp(ivec2(floor(st)), ivec2(0), ivec2(SHADOW_MAP_SIZE - 1));
    float lit = 0.0;
    for (int i = -SHADOW_FILTER_RADIUS; i <= SHADOW_FILTER_RADIUS; ++i) {
        for (int k = -SHADOW_FILTER_RADIUS; k <= SHADOW_FILTER_RADIUS; ++k) {
            ivec2 t = clamp(texel + ivec2(i, k), ivec2(0), ivec2(SHADOW_MAP_SIZE - 1));
            float stored = texelFetch(map, ivec2((face % 3) * SHADOW_MAP_SIZE + t.x, (face / 3) * SHADOW_MAP_SIZE + t.y), 0).r;
            lit += stored >= d - bias ? 1.0 : 0.0;
        }
    }
    return lit / float((2 * SHADOW_FILTER_RADIUS + 1) * (2 * SHADOW_FILTER_RADIUS + 1));
}

float shadow_ortho(sampler2D map, vec3 origin, vec3 axis, vec3 e1, vec3 e2, float texel_size, vec3 x, vec3 n)
{
    vec3 r = x - origin;
    float d = dot(r, axis);
    float offset = (float(SHADOW_FILTER_RADIUS) + 0.5) * 1.4142135623730951 * texel_size;
    float bias = shadow_bias(shadow_plane_length(abs(dot(n, axis)), offset), abs(d) + max_abs(x) + max_abs(origin));
    vec2 st = vec2(dot(e1, r), dot(e2, r));
    if (any(lessThan(st, vec2(0.0))) || any(greaterThanEqual(st, vec2(float(SHADOW_MAP_SIZE))))) {
        return 1.0;  // outside the map: no caster there
    }
    ivec2 texel = clamp(ivec2(floor(st)), ivec2(0), ivec2(SHADOW_MAP_SIZE - 1));
    float lit = 0.0;
    for (int i = -SHADOW_FILTER_RADIUS; i <= SHADOW_FILTER_RADIUS; ++i) {
        for (int k = -SHADOW_FILTER_RADIUS; k <= SHADOW_FILTER_RADIUS; ++k) {
            ivec2 t = clamp(texel + ivec2(i, k), ivec2(0), ivec2(SHADOW_MAP_SIZE - 1));
            lit += texelFetch(map, t, 0).r >= d - bias ? 1.0 : 0.0;
        }
    }
    return lit / float((2 * SHADOW_FILTER_RADIUS + 1) * (2 * SHADOW_FILTER_RADIUS + 1));
}
