// surface.glsl -- surface inputs: parameters that vary over a mesh (glphong/materials/surface.py).
//
//   u_<model>_<param> = scale * T(uv) * C          (material_inputs(), generated from the program key)
//   T(uv) = surface_texture(s, uv): the texture's linear rgb, GL_LINEAR_MIPMAP_LINEAR over glphong's
//           own mip pyramid (or GL_LINEAR); texels are linear (sRGB decoded on the CPU), float16/float32;
//   C     = the interpolated linear vertex colour, dimensionless.
// surface_texture_lod(s, uv) -> the level of detail texture() used at this fragment (textureQueryLOD(s, uv).x,
//   GL_ARB_texture_query_lod), written to the G-buffer so the twin blends the same two levels.  It has no
//   numpy twin on purpose: it reports the GPU's own choice, which the twin reads instead of recomputing.
// Called only from main(), in uniform control flow: the implicit derivatives are defined.
// Key defines read here: OUTPUT_GBUFFER, NUM_LOD_TEXTURES (surface_texture_lod exists only in a G-buffer program
//   that writes levels of detail).

vec3 surface_texture(sampler2D s, vec2 uv)
{
    return texture(s, uv).rgb;
}

#if OUTPUT_GBUFFER && NUM_LOD_TEXTURES > 0
float surface_texture_lod(sampler2D s, vec2 uv)
{
    return textureQueryLOD(s, uv).x;
}
#endif
