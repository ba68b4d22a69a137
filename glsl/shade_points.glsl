// shade_points.glsl -- vertex stage that shades arbitrary points (no rasterisation).
//
//   out_radiance = shade_point(in_position, shading_frame(safe_normalize(in_normal), in_tangent, in_uv), u_eye)
//   [W/(m^2 sr)].  The same shade_point() as the fragment stage, evaluated once per input point and
//   captured by transform feedback: the stability suite, the shader unit-testing toolkit and the
//   property tests drive the real shading code with exactly chosen inputs.  The normal is used as
//   given (no two-sided flip).
// Key defines read here: NEEDS_VIEW, HAS_TANGENT, HAS_UV.

in vec3 in_position;
in vec3 in_normal;
#if HAS_TANGENT
in vec4 in_tangent;
#endif
#if HAS_UV
in vec2 in_uv;
#endif
#if NEEDS_VIEW
uniform vec4 u_eye;  // homogeneous eye (e, w): the view vector at x is normalize(e - w x)
#else
const vec4 u_eye = vec4(0.0);  // no term reads the view: shade_point() never reads the eye
#endif
out vec3 out_radiance;

void main()
{
    vec3 n;
    float n_len;
    bool n_valid = safe_normalize(in_normal, n, n_len);
    vec4 tangent = vec4(0.0);
    vec2 uv = vec2(0.0);
#if HAS_TANGENT
    tangent = in_tangent;
#endif
#if HAS_UV
    uv = in_uv;
#endif
    out_radiance = shade_point(in_position, shading_frame(n, tangent, uv), n_valid, u_eye);
}
