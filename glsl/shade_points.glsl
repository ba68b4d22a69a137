// shade_points.glsl -- vertex stage that shades arbitrary points (no rasterisation).
//
//   out_radiance = shade_point(in_position, safe_normalize(in_normal), u_eye)   [W/(m^2 sr)]
// The same shade_point() as the fragment stage, evaluated once per input point and captured by
// transform feedback: the stability suite and the property tests drive the real shading
// code with exactly chosen inputs.  The normal is used as given (no two-sided flip).

in vec3 in_position;
in vec3 in_normal;
#if NEEDS_VIEW
uniform vec3 u_eye;
#else
const vec3 u_eye = vec3(0.0);  // no specular lobe: shade_point() never reads the eye
#endif
out vec3 out_radiance;

void main()
{
    vec3 n;
    float n_len;
    bool n_valid = safe_normalize(in_normal, n, n_len);
    out_radiance = shade_point(in_position, n, n_valid, u_eye);
}
