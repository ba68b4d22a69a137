// transmission_thin.glsl -- KHR_materials_transmission (thin walls) and, in it, KHR_materials_volume and
// KHR_materials_dispersion: what lies behind a transmissive surface, seen through it (glphong/materials/
// gltf_transmission.py, glphong/gpu/transmission.py, docs/transmission.md).  In the fragment stage of the radiance
// programs whose gltf_pbr term defines GLTF_PBR_TRANSMISSION, after the material chunks (it reads u_gltf_pbr_*).
//
//   L_t = (1 - m) t (1 - max3(F(n.v))) c B keep(n.v, n.v),   F(c) = fresnel_schlick(f0, c) = f0 + (1 - f0) (1 - c)^5
//   (library chunk fresnel.glsl: c clamped to [0, 1]),  f0 = ((ior - 1)/(ior + 1))^2
//   gltf_transmission_fresnel(ior, c) -> F (defined in materials/gltf_pbr.glsl, which KHR_materials_diffuse_transmission
//     also reads): fresnel_schlick(vec3(f0), c); with KHR_materials_specular
//     (GLTF_PBR_SPECULAR) specular fresnel_schlick(min(f0 specular_color, 1), c) = mix(min(f0 specular_color, 1)
//     specular, specular, (1 - c)^5), the specification's fresnel_mix F (gltf_pbr.glsl's gltf_specular_fresnel): the
//     transmitted light is in fresnel_mix's base, so it is weighted by 1 - max3(F) as the diffuse is.  With
//     KHR_materials_iridescence (GLTF_PBR_IRIDESCENCE) the film replaces it by F' = mix(F, F_iridescence(1,
//     iridescence_ior, film_f0, d, clamp(c, 0, 1)), iridescence), film_f0 = min(f0 specular_color, 1) specular (f0
//     without KHR_materials_specular), d = mix(thickness_minimum, thickness_maximum, thickness_mix)
//     (gltf_iridescence.glsl's gltf_iridescence_fresnel, as gltf_pbr.glsl's response mixes it): 1 - max3(F'), as the
//     specification's rgb_mix weights its base.
//   gltf_transmission_layers(f, wo, n_dot_v, n_dot_l) -> keep (defined in materials/gltf_pbr.glsl): what the layers over the base leave of the light it
//     lets through, as they weight the base: KHR_materials_sheen's albedo scaling gltf_sheen_scaling(n.v, n_dot_l) =
//     max(min(1 - max3(sheen_color) E(n.v), 1 - max3(sheen_color) E(n_dot_l)), 0) (GLTF_PBR_SHEEN; gltf_pbr.glsl)
//     times KHR_materials_clearcoat's 1 - clearcoat F_c(n.v) (GLTF_PBR_CLEARCOAT; gltf_clearcoat_fresnel), with a
//     coat normal 1 - clearcoat F_c(max(n_c.v, 0)) on the coat's own normal n_c = gltf_clearcoat_normal(f)
//     (GLTF_PBR_CLEARCOAT_NORMAL; gltf_pbr.glsl: its texel on the unperturbed frame, the coat's reflection's n_c);
//     1 without them.  n_dot_l: the light's |n.l| (a light behind: -n.wi, n.l' of its mirror; the background seen
//     straight through: n.v).
//   gltf_transmission_weight(n, wo, c, m, t, ior) -> (1 - m) t (1 - max3(F(n.v))) c
//   gltf_transmission_lod(roughness, ior) -> lod = u_transmission_levels roughness clamp(2 ior - 2, 0, 1)
//     (u_transmission_levels = log2 of the background's width: the glTF Sample Viewer's rule)
//   gltf_transmission_background(lod) -> B of a thin wall: lod = 0 (roughness 0, or ior 1): the background's texel
//     at this pixel, texelFetch (the straight-through ray: exact); lod > 0: gltf_transmission_sample at the pixel's
//     centre.
//   gltf_transmission_sample(uv, lod) -> textureLod: trilinear over the pyramid of 2x2 box means for lod > 0
//     (GL_LINEAR_MIPMAP_LINEAR), bilinear on level 0 for lod = 0; clamped to the edge.
// GLTF_PBR_VOLUME (KHR_materials_volume, thickness > 0; the Sample Viewer's approximation, the second interface not
// traced):
//   gltf_volume_ray(n, wo, eta, thickness) -> normalize(refract(-wo, n, 1/eta)) thickness s, s = the lengths of
//     u_model's three columns (the node's scale per axis, as the Sample Viewer applies it);
//   gltf_volume_uv(p) -> ((P p).xy / (P p).w + 1) / 2, P = u_view_projection: where the exit point x + ray projects;
//   gltf_volume_attenuation(d, (color, distance)) -> color^(d / distance) (Beer-Lambert), 1 for distance = FLT_MAX
//     (the specification's infinite distance) and for d <= 0 (no path: GLSL's pow(0, 0) is undefined);
//   gltf_volume_light(x, n, wo, eta, roughness) -> B = sample(uv of the exit, lod(roughness, eta)) times the
//     attenuation over |ray|.
//   a point, spot or directional light behind the surface (the generated light loops, glphong/shaders/generated.py,
//   as the model's behind_exits declare; the Sample Viewer's punctual loop): the transmission's BTDF
//   (gltf_transmission_response) takes the light seen from the exit point x + gltf_volume_exit(f, wo), its wi' and
//   E' there (the kind's incident at x + ray; gated on n.wi' < 0), times gltf_volume_exit_attenuation(f, wo);
//   the diffuse transmission's (gltf_diffuse_transmission_response, at x) times gltf_volume_diffuse_attenuation:
//   gltf_volume_exit(f, wo) -> gltf_volume_ray(n, wo, ior, thickness) (the material's ior: no dispersion);
//   gltf_volume_exit_attenuation(f, wo) -> gltf_volume_attenuation(|gltf_volume_exit(f, wo)|, (color, distance));
//   gltf_volume_diffuse_attenuation(f, wo) -> gltf_volume_attenuation(thickness (s_x + s_y + s_z)/3, (color,
//     distance)) (the Sample Viewer's diffuseTransmissionThickness: the path not refracted, the scale's mean).
// GLTF_PBR_DISPERSION (KHR_materials_dispersion, in a volume): the channels refract with iors ior -+ (ior - 1) 0.025
//   dispersion (red max(ior - h, 1), green ior, blue ior + h), each its own gltf_volume_light, as the Sample Viewer
//   does but for the red ior kept at 1 or above (KHR_materials_ior's range: below it a grazing view has no refracted
//   ray, refract() 0 and normalize(0) NaN).
// gltf_transmission_radiance(f, n_valid, x, eye) -> L_t on the shading frame f (n = f.n), 0 where n is invalid or
//   the view does not normalise; wo = normalize(eye.xyz - x eye.w) as shade.glsl forms it.
// gltf_transmission_response(f, wi, wo, n_dot_l) -> the BTDF of a punctual light behind the surface (n_dot_l = -n.wi
//   > 0; the generated light loops call it where n.wi < 0, glphong/shaders/generated.py), times n_dot_l: the thin
//   wall's BTDF, the light mirrored through the surface, l' = wi - 2 (n.wi) n:
//   (1 - m) t c (1 - max3(F(v.h'))) D V (n.l') keep(n.v, n_dot_l), h' = normalize(l' + v), D V (n.l') =
//   gltf_pbr_specular with alpha = roughness^2, the specification's (0 for roughness 0: a delta that a point light
//   meets with zero measure; the background's blur takes the Sample Viewer's ior factor instead: docs/transmission.md).
// u_transmission_background: the opaque scene's radiance drawn before the transmissive surfaces (RGBA32F, its levels).
// Key defines read here: GLTF_PBR_VOLUME, GLTF_PBR_DISPERSION, GLTF_PBR_SPECULAR, GLTF_PBR_SHEEN, GLTF_PBR_CLEARCOAT,
// GLTF_PBR_CLEARCOAT_NORMAL, GLTF_PBR_IRIDESCENCE.

uniform sampler2D u_transmission_background;
uniform float u_transmission_levels;
#if defined(GLTF_PBR_VOLUME)
uniform mat4 u_model;
uniform mat4 u_view_projection;
#endif

vec3 gltf_transmission_weight(vec3 n, vec3 wo, vec3 c, float m, float t, float ior)
{
    vec3 fresnel = gltf_transmission_fresnel(ior, dot(n, wo));
    return c * ((1.0 - m) * t * (1.0 - max(fresnel.r, max(fresnel.g, fresnel.b))));
}

float gltf_transmission_lod(float roughness, float ior)
{
    return u_transmission_levels * roughness * clamp(2.0 * ior - 2.0, 0.0, 1.0);
}

vec3 gltf_transmission_sample(vec2 uv, float lod)
{
    return textureLod(u_transmission_background, uv, lod).rgb;
}

vec3 gltf_transmission_background(float lod)
{
    vec3 texel = texelFetch(u_transmission_background, ivec2(gl_FragCoord.xy), 0).rgb;
    vec3 filtered = gltf_transmission_sample(gl_FragCoord.xy / vec2(textureSize(u_transmission_background, 0)), lod);
    return lod > 0.0 ? filtered : texel;
}

#if defined(GLTF_PBR_VOLUME)
vec3 gltf_volume_ray(vec3 n, vec3 wo, float eta, float thickness)
{
    vec3 r = refract(-wo, n, 1.0 / eta);
    vec3 scale = vec3(length(u_model[0].xyz), length(u_model[1].xyz), length(u_model[2].xyz));
    return normalize(r) * thickness * scale;
}

vec2 gltf_volume_uv(vec3 p)
{
    vec4 clip = u_view_projection * vec4(p, 1.0);
    return (clip.xy / clip.w + 1.0) * 0.5;
}

vec3 gltf_volume_attenuation(float d, vec4 attenuation)
{
    return attenuation.w >= FLT_MAX || d <= 0.0 ? vec3(1.0) : pow(attenuation.rgb, vec3(d / attenuation.w));
}

vec3 gltf_volume_light(vec3 x, vec3 n, vec3 wo, float eta, float roughness)
{
    vec3 ray = gltf_volume_ray(n, wo, eta, gltf_pbr_thickness());
    return gltf_transmission_sample(gltf_volume_uv(x + ray), gltf_transmission_lod(roughness, eta))
        * gltf_volume_attenuation(length(ray), gltf_pbr_attenuation());
}

vec3 gltf_volume_exit(ShadingFrame f, vec3 wo)
{
    return gltf_volume_ray(f.n, wo, u_gltf_pbr_ior, gltf_pbr_thickness());
}

vec3 gltf_volume_exit_attenuation(ShadingFrame f, vec3 wo)
{
    return gltf_volume_attenuation(length(gltf_volume_exit(f, wo)), gltf_pbr_attenuation());
}

vec3 gltf_volume_diffuse_attenuation(ShadingFrame f, vec3 wo)
{
    float scale = (length(u_model[0].xyz) + length(u_model[1].xyz) + length(u_model[2].xyz)) / 3.0;
    return gltf_volume_attenuation(gltf_pbr_thickness() * scale, gltf_pbr_attenuation());
}
#endif

vec3 gltf_transmission_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    vec3 mirrored = wi + (2.0 * n_dot_l) * f.n;
    float n_dot_v, n_dot_h, v_dot_h, tan2;
    bool valid = microfacet_geometry(f.n, mirrored, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, tan2);
    float alpha = u_gltf_pbr_roughness * u_gltf_pbr_roughness;
    float lobe = gltf_pbr_specular(alpha * alpha, tan2, n_dot_l, n_dot_v);
    vec3 fresnel = gltf_transmission_fresnel(u_gltf_pbr_ior, v_dot_h);
    float fresnel_max = max(fresnel.r, max(fresnel.g, fresnel.b));
    vec3 value = u_gltf_pbr_base_color * ((1.0 - u_gltf_pbr_metallic) * u_gltf_pbr_transmission * (1.0 - fresnel_max)
                                          * lobe);
    return valid ? value * gltf_transmission_layers(f, wo, n_dot_v, n_dot_l) : vec3(0.0);
}

vec3 gltf_transmission_radiance(ShadingFrame f, bool n_valid, vec3 x, vec4 eye)
{
    vec3 n = f.n;
    vec3 wo;
    float view_distance;
    bool valid = safe_normalize(eye.xyz - x * eye.w, wo, view_distance) && n_valid;
    float ior = u_gltf_pbr_ior;
    float roughness = u_gltf_pbr_roughness;
#if defined(GLTF_PBR_DISPERSION)
    float half_spread = (ior - 1.0) * 0.025 * gltf_pbr_dispersion();
    vec3 behind = vec3(gltf_volume_light(x, n, wo, max(ior - half_spread, 1.0), roughness).r,
                       gltf_volume_light(x, n, wo, ior, roughness).g,
                       gltf_volume_light(x, n, wo, ior + half_spread, roughness).b);
#elif defined(GLTF_PBR_VOLUME)
    vec3 behind = gltf_volume_light(x, n, wo, ior, roughness);
#else
    vec3 behind = gltf_transmission_background(gltf_transmission_lod(roughness, ior));
#endif
    float n_dot_v = max(dot(n, wo), 0.0);  // the straight-through ray: its |n.l| is n.v
    vec3 value = gltf_transmission_weight(n, wo, u_gltf_pbr_base_color, u_gltf_pbr_metallic, u_gltf_pbr_transmission,
                                          ior) * behind * gltf_transmission_layers(f, wo, n_dot_v, n_dot_v);
    return valid ? value : vec3(0.0);
}
