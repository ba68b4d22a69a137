// mesh_vertex.glsl -- vertex stage: object -> world -> clip space; per-vertex (Gouraud) shading.
//
//   world = M p;  n_world = N n  with N = inverse-transpose of M's 3x3 block (host, float64);
//   tangent_world = (M3 t.xyz, t.w)  (tangents move with the surface, not as normals);
//   gl_Position = (P V) world.
// Per-pixel shading (default): normal, tangent and uv are passed on unnormalised; the fragment stage shades.
// SHADE_PER_VERTEX: v_radiance = shade_point(world, frame, n_valid, u_eye) here, interpolated across the
//   triangle (Gouraud); the normal is flipped toward the eye when TWO_SIDED (a vertex shader has
//   no gl_FrontFacing); a vertex radiance beyond GOURAUD_MAX = 2^100 (about 1.3e30) saturates there, so
//   the interpolation never meets Inf (Inf times a zero barycentric weight is NaN) nor overflows.
//   Positions in metres, radiance in W/(m^2 sr).
// Attribute locations: 0 position, 1 normal, then TANGENT_LOCATION, UV_LOCATION, COLOR_LOCATION (the linear
// vertex colour: HAS_COLOR, a surface input reads it; material_inputs() runs here when shading per vertex):
// 2, 3 and 5 in glphong's own draws, pyrender's packed order inside pyrender (the key says which).
// Outputs are invariant so the radiance and the G-buffer programs interpolate identical inputs.
// HAS_OBJECT (G-buffer programs of the frame passes): v_object = p, the point in the object's own frame [m].
// Key defines read here: HAS_NORMAL, HAS_TANGENT, HAS_UV, HAS_COLOR, HAS_INPUTS, HAS_OBJECT, *_LOCATION, SHADE_PER_VERTEX,
// ALPHA_MASK, TWO_SIDED, NEEDS_VIEW, RUNTIME_SWITCHES, SWITCH(flag).

const float GOURAUD_MAX = 1.2676506002282294e30;  // 2^100: per-vertex radiance saturates here
layout(location = 0) in vec3 in_position;
uniform mat4 u_model;
uniform mat4 u_view_projection;
invariant gl_Position;
invariant out vec3 v_position;
#if HAS_NORMAL
layout(location = 1) in vec3 in_normal;
uniform mat3 u_normal_matrix;
#endif
#if HAS_TANGENT
layout(location = TANGENT_LOCATION) in vec4 in_tangent;
#endif
#if HAS_UV
layout(location = UV_LOCATION) in vec2 in_uv;
#endif
#if HAS_COLOR
layout(location = COLOR_LOCATION) in vec3 in_color;
#endif
#if SHADE_PER_VERTEX
out vec3 v_radiance;
#if NEEDS_VIEW
uniform vec4 u_eye;  // homogeneous eye (e, w): the view vector at x is normalize(e - w x)
#else
const vec4 u_eye = vec4(0.0);  // nothing reads the eye
#endif
#if TWO_SIDED && RUNTIME_SWITCHES
uniform float u_two_sided;
#endif
#if ALPHA_MASK == 2
invariant out vec2 v_uv;  // the fragment stage's alpha test reads the texture at the interpolated uv
#endif
#else
#if HAS_NORMAL
invariant out vec3 v_normal;
#endif
#if HAS_TANGENT
invariant out vec4 v_tangent;
#endif
#if HAS_UV
invariant out vec2 v_uv;
#endif
#if HAS_COLOR
invariant out vec3 v_color;
#endif
#if HAS_OBJECT
invariant out vec3 v_object;
#endif
#endif

void main()
{
    vec4 world = u_model * vec4(in_position, 1.0);
    v_position = world.xyz;
    vec4 tangent = vec4(0.0);
    vec2 uv = vec2(0.0);
#if HAS_TANGENT
    tangent = vec4(mat3(u_model) * in_tangent.xyz, in_tangent.w);
#endif
#if HAS_UV
    uv = in_uv;
#endif
#if SHADE_PER_VERTEX
#if HAS_INPUTS
#if HAS_COLOR
    material_inputs(uv, in_color);
#else
    material_inputs(uv, vec3(1.0));
#endif
#endif
    vec3 n = vec3(0.0);
    bool n_valid = false;
#if HAS_NORMAL
    float n_len;
    n_valid = safe_normalize(u_normal_matrix * in_normal, n, n_len);
#if TWO_SIDED
    if (SWITCH(u_two_sided) && dot(n, u_eye.xyz - world.xyz * u_eye.w) < 0.0) {
        n = -n;
    }
#endif
#endif
    // saturated at GOURAUD_MAX: interpolating Inf (or values near FLT_MAX, which the perspective-correct
    // interpolation scales by 1/w and subtracts) would give Inf and NaN inside the triangle
    v_radiance = min(shade_point(world.xyz, shading_frame(n, tangent, uv), n_valid, u_eye), vec3(GOURAUD_MAX));
#if ALPHA_MASK == 2
    v_uv = uv;
#endif
#else
#if HAS_NORMAL
    v_normal = u_normal_matrix * in_normal;
#endif
#if HAS_TANGENT
    v_tangent = tangent;
#endif
#if HAS_UV
    v_uv = uv;
#endif
#if HAS_COLOR
    v_color = in_color;
#endif
#if HAS_OBJECT
    v_object = in_position;
#endif
#endif
    gl_Position = u_view_projection * world;
}
