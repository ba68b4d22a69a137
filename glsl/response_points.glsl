// response_points.glsl -- vertex stage that evaluates a material's response at given directions.
//
//   out_response = [n.wi > 0] material_response(f, wi, wo, n.wi)      [1/sr]  (f_r (n.wi), RGB)
//   f = shading_frame(in_normal, in_tangent, in_uv);  in_wi, in_wo, in_normal: unit vectors (host-normalised).
// One evaluation per input row, captured by transform feedback: glphong.testing.evaluate runs a
// material's GLSL on exactly chosen direction pairs, with no scene, no light and no rasterisation.
// Key defines read here: HAS_TANGENT, HAS_UV.

in vec3 in_wi;
in vec3 in_wo;
in vec3 in_normal;
#if HAS_TANGENT
in vec4 in_tangent;
#endif
#if HAS_UV
in vec2 in_uv;
#endif
out vec3 out_response;

void main()
{
    vec4 tangent = vec4(0.0);
    vec2 uv = vec2(0.0);
#if HAS_TANGENT
    tangent = in_tangent;
#endif
#if HAS_UV
    uv = in_uv;
#endif
    ShadingFrame f = shading_frame(in_normal, tangent, uv);
    float n_dot_l = dot(f.n, in_wi);
    out_response = n_dot_l > 0.0 ? material_response(f, in_wi, in_wo, n_dot_l) : vec3(0.0);
}
