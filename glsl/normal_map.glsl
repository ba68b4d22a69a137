// normal_map.glsl -- a tangent-space normal map (glTF 2.0 normalTexture; glphong/materials/surface.py NormalMap).
//
//   m = 2 texel - 1                                  the texel's tangent-space normal, texel linear in [0, 1]
//   n' = normalize(t (s m.x) + b (s m.y) + n m.z)     s = normalTexture.scale (scales x and y only, as glTF says)
//
// surface_normal(n, t, b, texel, scale) -> n' [unit], in the frame of the interpolated normal n and the tangent t,
//   bitangent b of shading_frame() (b = sign(w) cross(n, t), glTF's); n itself where n' does not normalise (a texel
//   of (0.5, 0.5, 0.5) with scale 0).  Called in main() with the texel sampled in uniform control flow.
// unperturbed_frame (HAS_UNPERTURBED: a lit term needs 'unperturbed'): the ShadingFrame before the material's normal
//   map, shading_frame(n, tangent, uv) of the interpolated normal, set by main() (mesh_fragment.glsl) before shading;
//   read by a coat normal (materials/gltf_pbr.glsl), which KHR_materials_clearcoat takes on that frame.
// Key defines read here: HAS_UNPERTURBED.

vec3 surface_normal(vec3 n, vec3 t, vec3 b, vec3 texel, float scale)
{
    vec3 m = texel * 2.0 - 1.0;
    vec3 p = t * (m.x * scale) + b * (m.y * scale) + n * m.z;
    vec3 mapped;
    float len;
    return safe_normalize(p, mapped, len) ? mapped : n;
}

#if defined(HAS_UNPERTURBED) && HAS_UNPERTURBED
ShadingFrame unperturbed_frame;
#endif
