// mesh_fragment.glsl -- fragment stage: per-pixel shading, the G-buffer of its inputs, or the
// interpolated per-vertex radiance.
//
//   n = safe_normalize(+-v_normal)  (flipped on back faces when TWO_SIDED: two-sided shading);
//   f = shading_frame(n, v_tangent, v_uv)  (common.glsl: the tangent orthonormalised against n);
//   radiance output: vec4(shade_point(v_position, f, n_valid, u_eye), 1)  [W/(m^2 sr)], linear float;
//   SHADE_PER_VERTEX: vec4(v_radiance, 1), the Gouraud-interpolated vertex radiance;
//   OUTPUT_DISPLAY (pyrender's 8-bit framebuffer): vec4(srgb_encode(u_exposure * L), 1);
//   G-buffer outputs (OUTPUT_GBUFFER): position (world, [m]) with w = object id + 1, the
//   normal exactly as shade_point() would use it (0 where it is invalid), w = 1; with HAS_TANGENT
//   the interpolated tangent (xyz, handedness w), with HAS_UV the uv (xy): the inputs of shading_frame();
//   locations 0 position, 1 normal, then tangent and uv in that order, packed (uv at 2 without a tangent).
// Key defines read here: HAS_NORMAL, HAS_TANGENT, HAS_UV, TWO_SIDED, OUTPUT_GBUFFER, OUTPUT_DISPLAY,
// SHADE_PER_VERTEX, NEEDS_VIEW, RUNTIME_SWITCHES, SWITCH(flag).

invariant in vec3 v_position;
#if SHADE_PER_VERTEX
in vec3 v_radiance;
layout(location = 0) out vec4 out_radiance;

void main()
{
    out_radiance = vec4(v_radiance, 1.0);
}
#else
#if HAS_NORMAL
invariant in vec3 v_normal;
#endif
#if HAS_TANGENT
invariant in vec4 v_tangent;
#endif
#if HAS_UV
invariant in vec2 v_uv;
#endif
#if TWO_SIDED && RUNTIME_SWITCHES
uniform float u_two_sided;
#endif
#if OUTPUT_GBUFFER
uniform float u_object_id;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
#if HAS_TANGENT
layout(location = 2) out vec4 out_tangent;
#endif
#if HAS_UV && HAS_TANGENT
layout(location = 3) out vec4 out_uv;
#elif HAS_UV
layout(location = 2) out vec4 out_uv;  // the renderer packs the extra planes: uv follows the normal when there is no tangent
#endif
#else
#if NEEDS_VIEW
uniform vec4 u_eye;  // homogeneous eye (e, w): the view vector at x is normalize(e - w x)
#else
const vec4 u_eye = vec4(0.0);  // no term reads the view: shade_point() never reads the eye
#endif
#if OUTPUT_DISPLAY
uniform float u_exposure;
#endif
layout(location = 0) out vec4 out_radiance;
#endif

void main()
{
    vec3 n = vec3(0.0);
    bool n_valid = false;
#if HAS_NORMAL
    vec3 n_raw = v_normal;
#if TWO_SIDED
    n_raw = (SWITCH(u_two_sided) && !gl_FrontFacing) ? -n_raw : n_raw;
#endif
    float n_len;
    n_valid = safe_normalize(n_raw, n, n_len);
#endif
    vec4 tangent = vec4(0.0);
    vec2 uv = vec2(0.0);
#if HAS_TANGENT
    tangent = v_tangent;
#endif
#if HAS_UV
    uv = v_uv;
#endif
#if OUTPUT_GBUFFER
    out_position = vec4(v_position, u_object_id + 1.0);
    out_normal = vec4(n, 1.0);
#if HAS_TANGENT
    out_tangent = tangent;
#endif
#if HAS_UV
    out_uv = vec4(uv, 0.0, 1.0);
#endif
#elif OUTPUT_DISPLAY
    out_radiance = vec4(srgb_encode(u_exposure * shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye)), 1.0);
#else
    out_radiance = vec4(shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye), 1.0);
#endif
}
#endif
