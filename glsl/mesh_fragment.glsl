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
//   with HAS_COLOR the interpolated vertex colour (rgb); with HAS_LOD the level of detail of each of the
//   object's NUM_LOD_TEXTURES textures (gbuffer_levels_of_detail(), generated; 0 beyond): the inputs of
//   material_inputs();
//   locations 0 position, 1 normal, then the extra planes at PLANE_<PLANE>_LOCATION (defines.py packs them).
// HAS_INPUTS: material_inputs(uv, colour) sets the surface inputs (the generated material chunk) before shading.
// ALPHA_MASK (1 constant, 2 textured alpha): fragments with alpha below the cutoff are discarded, in every program
//   that draws the object's surface (radiance, G-buffer, per-vertex), so the G-buffer covers what the radiance does.
// NORMAL_MAP: n = surface_normal(shading_frame(n, tangent, uv), texture(u_normal_map_texture, uv).rgb, scale)
//   (normal_map.glsl) where n is valid, before the G-buffer is written and before shading: both see the mapped normal.
// HAS_UNPERTURBED: a radiance program keeps the frame before the map in unperturbed_frame (normal_map.glsl); a G-buffer
//   program writes the normal before the map (n where there is none) at PLANE_UNPERTURBED_LOCATION.
// HAS_FACE: the triangle's own normal, from the derivatives of the interpolated position (the slope of the shadow
//   bias, shadows.glsl): a G-buffer plane, and shadow_face_normal when shading.
// HAS_OBJECT: the G-buffer plane of the point in the object's own frame (xyz [m], w = 1), for the frame passes.
// WRITES_PLANES (G-buffer programs, and radiance programs of the frame passes: multiple render targets beside the
//   radiance): the position plane (w = object id + 1) at PLANE_POSITION_LOCATION and, with PLANE_NORMAL,
//   PLANE_OBJECT, PLANE_UV, the normal, object and uv planes at their PLANE_*_LOCATION, the same in either program.
// NAIVE_NORMAL: n by plain_normalize where the key proves it safe, common.glsl.
// ALPHA_BLEND (defined only in a blended surface's layer programs, glphong/gpu/peeling.py, docs/design.md section 16;
//   per-pixel shading only): with z = gl_FragCoord.z (the window depth, float32) and
//   z_k = texelFetch(u_blend_depth, pixel).r:
//   2 (the peel): discard where z <= z_k (the previous layer's depth; -1 before the first, or before the background's
//     first the transmissive surfaces' nearest depth, which their own kind 2 programs draw); out = vec4(z), which the
//     renderer MIN-blends, so the target keeps the nearest depth behind the previous layer exactly;
//   1 (the layer): out = vec4(a L, a), a = u_alpha_blend: premultiplied, composited front to back by the blend unit
//     (C += (1 - A) c, A += (1 - A) a); discarded at the end where z != z_k (this layer's depth), so textures are
//     sampled in uniform control flow; 3: the same with a = u_alpha_blend * texture(u_alpha_blend_texture, uv).r.
// Key defines read here: HAS_NORMAL, HAS_TANGENT, HAS_UV, HAS_COLOR, HAS_INPUTS, HAS_LOD, HAS_FACE, HAS_OBJECT, HAS_UNPERTURBED, NUM_LOD_TEXTURES,
// WRITES_PLANES, PLANE_NORMAL, PLANE_OBJECT, PLANE_UV, PLANE_*_LOCATION, TWO_SIDED, OUTPUT_GBUFFER, OUTPUT_DISPLAY, SHADE_PER_VERTEX, NEEDS_VIEW, NORMAL_MAP, ALPHA_MASK,
// GLTF_PBR_TRANSMISSION (a radiance program of a transmissive gltf_pbr, glphong/gpu/transmission.py): after shading,
//   out += gltf_transmission_radiance(...) (transmission_thin.glsl), what lies behind the surface seen through it.
// NAIVE_NORMAL, RUNTIME_SWITCHES, SWITCH(flag), ALPHA_BLEND, GLTF_PBR_TRANSMISSION.

invariant in vec3 v_position;
#ifdef ALPHA_BLEND
uniform sampler2D u_blend_depth;  // the previous layer's window depth (ALPHA_BLEND 2) or this layer's (1, 3)
uniform float u_alpha_blend;      // read by the layer (1, 3) alone
#if ALPHA_BLEND == 3
uniform sampler2D u_alpha_blend_texture;
#endif
#endif
#if ALPHA_MASK
uniform float u_alpha_mask_cutoff;
uniform float u_alpha_mask_scale;
#endif
#if ALPHA_MASK == 2
uniform sampler2D u_alpha_mask_texture;
#endif

#if ALPHA_MASK
// the alpha test (glTF alphaMode MASK): alpha = scale (times texture(u_alpha_mask_texture, uv).r); the caller
// discards the fragment where alpha < cutoff (the texture sampled in uniform control flow, before any discard)
bool alpha_masked(vec2 uv)
{
    float alpha = u_alpha_mask_scale;
#if ALPHA_MASK == 2
    alpha *= surface_texture(u_alpha_mask_texture, uv).r;
#endif
    return alpha < u_alpha_mask_cutoff;
}
#endif

#if SHADE_PER_VERTEX
in vec3 v_radiance;
layout(location = 0) out vec4 out_radiance;
#if ALPHA_MASK == 2
invariant in vec2 v_uv;
#endif

void main()
{
#if ALPHA_MASK == 2
    if (alpha_masked(v_uv)) {
        discard;
    }
#elif ALPHA_MASK
    if (alpha_masked(vec2(0.0))) {
        discard;
    }
#endif
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
#if HAS_COLOR
invariant in vec3 v_color;
#endif
#if TWO_SIDED && RUNTIME_SWITCHES
uniform float u_two_sided;
#endif
#if NORMAL_MAP
uniform sampler2D u_normal_map_texture;
uniform float u_normal_map_scale;
#endif
#if WRITES_PLANES
uniform float u_object_id;
layout(location = PLANE_POSITION_LOCATION) out vec4 out_position;
#if PLANE_NORMAL
layout(location = PLANE_NORMAL_LOCATION) out vec4 out_normal;
#endif
#if PLANE_OBJECT
invariant in vec3 v_object;
layout(location = PLANE_OBJECT_LOCATION) out vec4 out_object;
#endif
#if PLANE_UV
layout(location = PLANE_UV_LOCATION) out vec4 out_uv;
#endif
#endif
#if OUTPUT_GBUFFER
#if HAS_TANGENT
layout(location = PLANE_TANGENT_LOCATION) out vec4 out_tangent;
#endif
#if HAS_COLOR
layout(location = PLANE_COLOR_LOCATION) out vec4 out_color;
#endif
#if HAS_LOD
layout(location = PLANE_LOD_LOCATION) out vec4 out_lod;
#endif
#if HAS_FACE
layout(location = PLANE_FACE_LOCATION) out vec4 out_face;
#endif
#if HAS_UNPERTURBED
layout(location = PLANE_UNPERTURBED_LOCATION) out vec4 out_unperturbed;
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
#ifdef ALPHA_BLEND
    float layer_depth = texelFetch(u_blend_depth, ivec2(gl_FragCoord.xy), 0).r;
#if ALPHA_BLEND == 2
    if (gl_FragCoord.z <= layer_depth) {
        discard;
    }
    out_radiance = vec4(gl_FragCoord.z);
    return;
#endif
#endif
    vec3 n = vec3(0.0);
    bool n_valid = false;
#if HAS_NORMAL
    vec3 n_raw = v_normal;
#if TWO_SIDED
    n_raw = (SWITCH(u_two_sided) && !gl_FrontFacing) ? -n_raw : n_raw;
#endif
    float n_len;
#if NAIVE_NORMAL
    n_valid = plain_normalize(n_raw, n, n_len);
#else
    n_valid = safe_normalize(n_raw, n, n_len);
#endif
#endif
    vec4 tangent = vec4(0.0);
    vec2 uv = vec2(0.0);
#if HAS_TANGENT
    tangent = v_tangent;
#endif
#if HAS_UV
    uv = v_uv;
#endif
    vec3 color = vec3(1.0);
#if HAS_COLOR
    color = v_color;
#endif
#if ALPHA_MASK
    if (alpha_masked(uv)) {
        discard;
    }
#endif
#ifdef ALPHA_BLEND
    float blend_alpha = u_alpha_blend;
#if ALPHA_BLEND == 3
    blend_alpha *= surface_texture(u_alpha_blend_texture, uv).r;  // in uniform control flow: implicit derivatives
#endif
#endif
#if HAS_UNPERTURBED && OUTPUT_GBUFFER
    out_unperturbed = vec4(n, 1.0);  // the normal before the map
#endif
#if NORMAL_MAP
    vec3 texel = surface_texture(u_normal_map_texture, uv);  // in uniform control flow: implicit derivatives
    ShadingFrame geometric = shading_frame(n, tangent, uv);
#if HAS_UNPERTURBED && !OUTPUT_GBUFFER
    unperturbed_frame = geometric;  // the frame before the map, for a term that needs 'unperturbed' (normal_map.glsl)
#endif
    n = n_valid ? surface_normal(geometric.n, geometric.t, geometric.b, texel, u_normal_map_scale) : n;
#endif
#if HAS_FACE
    // the triangle's own normal, from the derivatives of the interpolated position (the plane the shadow map
    // samples; either orientation): the slope of the shadow bias (glsl/shadows.glsl)
    vec3 face;
    float face_len;
    if (!safe_normalize(cross(dFdx(v_position), dFdy(v_position)), face, face_len)) {
        face = n;
    }
#endif
#if OUTPUT_GBUFFER
#if HAS_TANGENT
    out_tangent = tangent;
#endif
#if HAS_COLOR
    out_color = vec4(color, 1.0);
#endif
#if HAS_LOD && NUM_LOD_TEXTURES > 0
    out_lod = gbuffer_levels_of_detail(uv);  // the generated levels-of-detail chunk
#elif HAS_LOD
    out_lod = vec4(0.0);                     // another object of the scene has textures, this one none
#endif
#if HAS_FACE
    out_face = vec4(face, 1.0);
#endif
#else
#if HAS_INPUTS
    material_inputs(uv, color);
#endif
#if HAS_FACE
    shadow_face_normal = face;
#endif
#if OUTPUT_DISPLAY
    out_radiance = vec4(srgb_encode(u_exposure * shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye)), 1.0);
#elif defined(ALPHA_BLEND)
    out_radiance = blend_alpha * vec4(shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye), 1.0);
    if (gl_FragCoord.z != layer_depth) {  // not this layer's fragment: at the end, after every texture lookup
        discard;
    }
#else
    out_radiance = vec4(shade_point(v_position, shading_frame(n, tangent, uv), n_valid, u_eye), 1.0);
#if defined(GLTF_PBR_TRANSMISSION) && !defined(ALPHA_BLEND) && !SHADE_PER_VERTEX  // transmission_thin.glsl
    out_radiance.rgb += gltf_transmission_radiance(shading_frame(n, tangent, uv), n_valid, v_position, u_eye);
#endif
#endif
#endif
#if WRITES_PLANES
    out_position = vec4(v_position, u_object_id + 1.0);  // the G-buffer's planes, in either program
#if PLANE_NORMAL
    out_normal = vec4(n, 1.0);
#endif
#if PLANE_OBJECT
    out_object = vec4(v_object, 1.0);
#endif
#if PLANE_UV
    out_uv = vec4(uv, 0.0, 1.0);
#endif
#endif
}
#endif
