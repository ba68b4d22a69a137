// mesh_vertex.glsl -- vertex stage: object -> world -> clip space.
//
//   world = M p;  n_world = N n  with N = inverse-transpose of M's 3x3 block (host, float64);
//   gl_Position = (P V) world.
// Positions in metres.  The normal is passed on unnormalised; the fragment stage renormalises it.
// Outputs are invariant so the radiance and the G-buffer programs interpolate identical inputs.
// Key defines read here: HAS_NORMAL.

in vec3 in_position;
uniform mat4 u_model;
uniform mat4 u_view_projection;
invariant gl_Position;
invariant out vec3 v_position;
#if HAS_NORMAL
in vec3 in_normal;
uniform mat3 u_normal_matrix;
invariant out vec3 v_normal;
#endif

void main()
{
    vec4 world = u_model * vec4(in_position, 1.0);
    v_position = world.xyz;
#if HAS_NORMAL
    v_normal = u_normal_matrix * in_normal;
#endif
    gl_Position = u_view_projection * world;
}
