// materials/gltf_pbr.glsl -- the model 'gltf_pbr': glTF 2.0's metallic-roughness material as its specification's
// Appendix B writes it (docs/design.md section 9; glphong/materials/gltf_pbr.py), branchless, never NaN or Inf.
//
//   alpha = roughness^2;  x = (1 - |v.h|)^5
//   D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)                                   GGX (Trowbridge-Reitz)
//   V = 1 / (2 (|n.v| sqrt(alpha^2 + (1 - alpha^2)(n.l)^2) + |n.l| sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))
//                                                                                   height-correlated Smith
//   metal = (c + (1 - c) x) V D;   dielectric = mix(c/pi, V D, f0 + (1 - f0) x);   c = base_color
//   f0 = ((ior - 1)/(ior + 1))^2 (KHR_materials_ior; the core specification's ior 1.5 gives 0.04)
//   f_r = mix(dielectric, metal, metallic);   response = f_r (n.l)
//
// microfacet_geometry (library chunk microfacet.glsl): valid, n.v, n.h, v.h = |l + v|/2, tan2 = tan^2(theta_h) from the
//   chord (no 1 - (n.h)^2 cancellation at the peak); invalid where l = -v, n.v <= 0 or n.l <= 0 (the response is 0).
// microfacet_ggx(tan2, a2) (library chunk microfacet.glsl) -> GGX D = (a2 r) r / pi, r = (1 + tan2)/(a2 + tan2): the
//   specification's D divided through by (n.h)^4; 0 where a2 + tan2 = 0 (roughness 0 at the exact mirror direction:
//   a delta that no point light meets with nonzero measure, so this program reflects none of it).
// gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2) -> V (n.l) = n.l / (2 (n.v r_l + n.l r_v)),
//   r_x = sqrt((n.x)^2 + a2 (1 - (n.x)^2)): the response's n.l cancels the 1/(n.l) of V, so a grazing light
//   never forms 1/(n.l); at most 1 / (4 n.v) for roughness 0.
// gltf_pbr_specular(a2, tan2, n_dot_l, n_dot_v) -> the GGX lobe D V (n.l) of the base and of the coat, min(., FLT_MAX)
//   where a2 > 0, 0 where a2 = 0 (roughness 0: D is a delta; V's r_x would underflow to 0/0 for grazing l and v).
// KHR_materials_specular (GLTF_PBR_SPECULAR; glphong/materials/gltf_extensions.py, docs/gltf_extensions.md):
//   gltf_specular_fresnel(f0, specular, specular_color, x) -> F_d = mix(min(f0 specular_color, 1) specular, specular, x)
//   (rgb): the dielectric = F_d V D + (1 - max(F_d.r, F_d.g, F_d.b)) c/pi; the metal unchanged.
// KHR_materials_clearcoat (GLTF_PBR_CLEARCOAT): gltf_clearcoat_fresnel(n_dot_v) -> F_c = 0.04 + 0.96 (1 - n.v)^5
//   (fresnel_coat with ior 1.5, on n.v); f_r = mix(f_r, V_c D_c, clearcoat F_c), alpha_c = clearcoat_roughness^2, the
//   coat's normal the shading normal n; with GLTF_PBR_CLEARCOAT_NORMAL (clearcoatNormalTexture, or a base normal map;
//   reads f.t, f.b: the material then needs 'tangent', 'unperturbed', and the library chunk normal_map.glsl;
//   glphong/materials/gltf_coat_normal.py) gltf_clearcoat_normal(f) -> n_c = surface_normal(n, t, b, texel, scale) =
//   normalize(t (s m.x) + b (s m.y) + n m.z), m = 2 texel - 1 (the base normal map's rule, normal_map.glsl) on the
//   unperturbed frame (t, b, n): f, or where the material's normal map perturbed f (HAS_UNPERTURBED)
//   unperturbed_frame, the frame before the map (normal_map.glsl); the coat is D_c V_c (n_c.l) on n_c (0 where n_c.l
//   or n_c.v <= 0) weighted by clearcoat F_c(max(n_c.v, 0)), also over the light let through (transmission_thin.glsl).
// KHR_materials_sheen (GLTF_PBR_SHEEN; glphong/materials/gltf_sheen.py): alpha_g = sheen_roughness^2,
//   gltf_sheen_distribution(tan2, alpha_g) -> Charlie D = (2 + 1/alpha_g) sin2h^(1/(2 alpha_g)) / (2 pi), sin2h =
//   tan2/(1 + tan2) (from the chord: no 1 - (n.h)^2 cancellation); 0 for alpha_g = 0 (a delta at n.h = 0, which no
//   pair above the surface meets);
//   gltf_sheen_lambda(cos, alpha_g) -> exp(l(cos)) below 0.5, exp(2 l(0.5) - l(1 - cos)) above, l(x) = a/(1 + b x^c)
//   + d x + e with a..e mixed by (1 - alpha_g)^2 (the specification's fit);
//   sheen V (n.l) = 1 / ((1 + lambda(n.v) + lambda(n.l)) 4 n.v) (the response's n.l cancels V's);
//   gltf_sheen_albedo(cos, sheen_roughness) -> E: bilinear in the table GLTF_SHEEN_E at sqrt(cos) 32 and
//   sheen_roughness 16 (E integrated in float64 from this lobe: benchmarks/gltf_sheen_albedo.py);
//   gltf_sheen_scaling(n_dot_v, n_dot_l) -> max(min(1 - max3(sheen_color) E(n.v), 1 - max3(sheen_color) E(n.l)), 0)
//   (the specification's albedo scaling, clamped at 0 where E max3(sheen_color) > 1; also transmission_thin.glsl's,
//   over the light let through); f_r = sheen_color D V + f_r gltf_sheen_scaling(n.v, n.l), then the coat over it.
// KHR_materials_anisotropy (GLTF_PBR_ANISOTROPY; glphong/materials/gltf_anisotropy.py; reads f.t, f.b: the material
//   then needs 'tangent'): gltf_anisotropy_frame(n, t, b, texel, rotation, out T, out B): d = rotate(normalize(2
//   texel.rg - 1), rotation) ((1, 0) where it is 0), T = normalize(d.x t + d.y b), B = normalize(n x T);
//   gltf_anisotropy_ggx(n.h, T.h, B.h, at, ab) -> D = 1 / (pi at ab s^2), s = (T.h/at)^2 + (B.h/ab)^2 + (n.h)^2 (the
//   specification's a2 w2^2 / pi divided through by a2^2: positive terms);
//   gltf_anisotropy_visibility_cos(...) -> clamp(V, 0, 1) (n.l) = min(0.5 n.l / (n.l |(at T.v, ab B.v, n.v)| + n.v
//   |(at T.l, ab B.l, n.l)|), n.l) (the specification's V_GGX_anisotropic, n.l cancelled);
//   gltf_anisotropy_specular(T, B, wi, wo, n.l, n.v, n.h, v.h, alpha, strength): at = mix(alpha, 1, strength^2), ab =
//   alpha, T.h = (T.l + T.v)/(2 v.h), B.h likewise (h = (l + v)/|l + v|, |l + v| = 2 v.h from microfacet_geometry,
//   as its n.h); D V (n.l) in place of the base's isotropic lobe, 0 where at ab = 0 (a delta).
// Uniforms (declared by glphong from the model's params): u_gltf_pbr_base_color, u_gltf_pbr_metallic,
// u_gltf_pbr_roughness, u_gltf_pbr_ior, u_gltf_pbr_specular, u_gltf_pbr_specular_color, u_gltf_pbr_clearcoat,
// u_gltf_pbr_clearcoat_roughness, u_gltf_pbr_sheen_color, u_gltf_pbr_sheen_roughness, u_gltf_pbr_anisotropy_strength,
// u_gltf_pbr_anisotropy_rotation, u_gltf_pbr_anisotropy_direction, u_gltf_pbr_clearcoat_normal,
// u_gltf_pbr_clearcoat_normal_strength (u_gltf_pbr_emissive and
// u_gltf_pbr_occlusion are read by generated code).
// KHR_materials_transmission (GLTF_PBR_TRANSMISSION; glphong/materials/gltf_transmission.py): a light on the viewer's
//   side meets no BTDF, so the diffuse is weighted by 1 - transmission; what lies behind is added after shading
//   (glsl/transmission_thin.glsl).
// KHR_materials_iridescence (GLTF_PBR_IRIDESCENCE): gltf_iridescence_parts (materials/gltf_iridescence.glsl, read before
//   this file) replaces the Fresnel factor, F = mix(F, F_iridescence, iridescence), dielectric and metal, and the
//   max(F_d) that weights the diffuse; the film's base_f0 = gltf_specular_fresnel(f0, specular, specular_color, 0) =
//   min(f0 specular_color, 1) specular with KHR_materials_specular, f0 without.
// KHR_materials_diffuse_transmission (GLTF_PBR_DIFFUSE_TRANSMISSION; glphong/materials/gltf_diffuse_transmission.py):
//   a light in front sees the diffuse times 1 - dt (dt = u_gltf_pbr_diffuse_transmission); a light behind,
//   gltf_diffuse_transmission_response(f, wi, wo, n_dot_l), n_dot_l = -n.wi > 0 (called by the generated light loops
//   where n.wi < 0, glphong/shaders/generated.py):
//   (1 - m) (1 - t) dt (c_dt / pi) (1 - max3(F(v.h'))) n_dot_l keep(n.v, n_dot_l), l' = wi + 2 n_dot_l n,
//   h' = normalize(l' + v), F = gltf_transmission_fresnel (f0 + (1 - f0) (1 - v.h')^5; with KHR_materials_specular
//   its fresnel_mix F, the diffuse BTDF being in the dielectric's base; with KHR_materials_iridescence the film's
//   F' = mix(F, F_iridescence, iridescence)), keep = gltf_transmission_layers (the sheen's
//   albedo scaling times the coat's 1 - clearcoat F_c; both defined below, their formulas in transmission_thin.glsl),
//   c_dt = u_gltf_pbr_diffuse_transmission_color, t the transmission (0 without it).
// Key defines read here: HAS_UNPERTURBED, GLTF_PBR_DIFFUSE_TRANSMISSION, GLTF_PBR_IRIDESCENCE, GLTF_PBR_ANISOTROPY, GLTF_PBR_CLEARCOAT_NORMAL, GLTF_PBR_SPECULAR, GLTF_PBR_CLEARCOAT, GLTF_PBR_SHEEN, GLTF_PBR_TRANSMISSION, GLTF_PBR_VOLUME (defined where the material uses the
// extension: its code is not in the program otherwise).

const float GLTF_PBR_INV_PI = 0.3183098861837907;

float gltf_pbr_visibility_cos(float n_dot_l, float n_dot_v, float a2)
{
    float r_l = sqrt(n_dot_l * n_dot_l + a2 * (1.0 - n_dot_l * n_dot_l));
    float r_v = sqrt(n_dot_v * n_dot_v + a2 * (1.0 - n_dot_v * n_dot_v));
    return n_dot_l / (2.0 * (n_dot_v * r_l + n_dot_l * r_v));
}

float gltf_pbr_specular(float a2, float tan2, float n_dot_l, float n_dot_v)
{
    return a2 > 0.0 ? min(microfacet_ggx(tan2, a2) * gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2), FLT_MAX) : 0.0;
}

#if defined(GLTF_PBR_ANISOTROPY)
void gltf_anisotropy_frame(vec3 n, vec3 t, vec3 b, vec3 texel, float rotation, out vec3 aniso_t, out vec3 aniso_b)
{
    vec3 d;
    float len;
    bool ok = safe_normalize(vec3(texel.rg * 2.0 - 1.0, 0.0), d, len);
    float dx = ok ? d.x : 1.0;
    float dy = ok ? d.y : 0.0;
    float c = cos(rotation);
    float s = sin(rotation);
    float rx = c * dx - s * dy;
    float ry = s * dx + c * dy;
    ok = safe_normalize(t * rx + b * ry, aniso_t, len);
    aniso_t = ok ? aniso_t : t;
    ok = safe_normalize(cross(n, aniso_t), aniso_b, len);
    aniso_b = ok ? aniso_b : b;
}

float gltf_anisotropy_ggx(float n_dot_h, float t_dot_h, float b_dot_h, float at, float ab)
{
    float x = t_dot_h / at;
    float y = b_dot_h / ab;
    float s = x * x + y * y + n_dot_h * n_dot_h;
    return GLTF_PBR_INV_PI / ((at * ab) * (s * s));
}

float gltf_anisotropy_visibility_cos(float n_dot_l, float n_dot_v, float t_dot_l, float b_dot_l, float t_dot_v,
                                     float b_dot_v, float at, float ab)
{
    float ggx_v = n_dot_l * sqrt(at * t_dot_v * (at * t_dot_v) + ab * b_dot_v * (ab * b_dot_v) + n_dot_v * n_dot_v);
    float ggx_l = n_dot_v * sqrt(at * t_dot_l * (at * t_dot_l) + ab * b_dot_l * (ab * b_dot_l) + n_dot_l * n_dot_l);
    return min(0.5 * n_dot_l / (ggx_v + ggx_l), n_dot_l);
}

float gltf_anisotropy_specular(vec3 aniso_t, vec3 aniso_b, vec3 wi, vec3 wo, float n_dot_l, float n_dot_v,
                               float n_dot_h, float v_dot_h, float alpha, float strength)
{
    float t_dot_l = dot(aniso_t, wi);
    float b_dot_l = dot(aniso_b, wi);
    float t_dot_v = dot(aniso_t, wo);
    float b_dot_v = dot(aniso_b, wo);
    float h_len = 2.0 * v_dot_h;  // |l + v| (1 where invalid): microfacet_geometry's n.h = (n.l + n.v)/|l + v|
    float at = alpha * (1.0 - strength * strength) + strength * strength;  // mix(alpha, 1, strength^2)
    float ab = alpha;
    float d = gltf_anisotropy_ggx(n_dot_h, (t_dot_l + t_dot_v) / h_len, (b_dot_l + b_dot_v) / h_len, at, ab);
    float v_cos = gltf_anisotropy_visibility_cos(n_dot_l, n_dot_v, t_dot_l, b_dot_l, t_dot_v, b_dot_v, at, ab);
    return at * ab > 0.0 ? min(d * v_cos, FLT_MAX) : 0.0;
}
#endif

#if defined(GLTF_PBR_SPECULAR)
vec3 gltf_specular_fresnel(float f0, float specular, vec3 specular_color, float x)
{
    vec3 dielectric_f0 = min(f0 * specular_color, vec3(1.0)) * specular;
    return dielectric_f0 + (specular - dielectric_f0) * x;
}
#endif

#if defined(GLTF_PBR_CLEARCOAT)
float gltf_clearcoat_fresnel(float n_dot_v)
{
    float y1 = max(1.0 - n_dot_v, 0.0);
    float y = (y1 * y1) * (y1 * y1) * y1;
    return 0.04 + 0.96 * y;
}

#if defined(GLTF_PBR_CLEARCOAT_NORMAL)
vec3 gltf_clearcoat_normal(ShadingFrame f)
{
#if defined(HAS_UNPERTURBED) && HAS_UNPERTURBED  // a base normal map perturbed f: the frame before it
    ShadingFrame g = unperturbed_frame;
#else
    ShadingFrame g = f;
#endif
    return surface_normal(g.n, g.t, g.b, u_gltf_pbr_clearcoat_normal, u_gltf_pbr_clearcoat_normal_strength);
}
#endif
#endif

#if defined(GLTF_PBR_SHEEN)
// BEGIN sheen albedo table (generated by benchmarks/gltf_sheen_albedo.py)
const float GLTF_SHEEN_E[561] = float[](
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0,
    0.0,
    3.2440185546875, 3.2440185546875, 3.149132490158081, 2.7943196296691895,
    2.3529767990112305, 1.905053973197937, 1.489885926246643, 1.1263418197631836,
    0.8218964338302612, 0.5771691203117371, 0.3884377181529999, 0.2492275834083557,
    0.1514892578125, 0.08658286929130554, 0.04612554609775543, 0.022670721635222435,
    0.01015800517052412, 0.004091485403478146, 0.0014571562642231584, 0.0004499466740526259,
    0.00011765837552957237, 2.5320519853266887e-05, 4.3289542190905195e-06, 5.624568188977719e-07,
    5.247361301030651e-08, 3.2574316577438367e-09, 1.2113561542737017e-10, 2.318277514401501e-12,
    1.805809530228998e-14, 3.8449826487135035e-17, 1.0220956264815618e-20, 4.39223946961218e-26,
    6.710818345651549e-42,
    1.7094889879226685, 1.7094889879226685, 1.7413678169250488, 1.6476634740829468,
    1.5003830194473267, 1.332389235496521, 1.1605926752090454, 0.9942259192466736,
    0.838441789150238, 0.6960726976394653, 0.5685507655143738, 0.4564104676246643,
    0.3595728576183319, 0.2775135636329651, 0.20937058329582214, 0.15402238070964813,
    0.11015470325946808, 0.07632463425397873, 0.05102568492293358, 0.03275340795516968,
    0.020068589597940445, 0.011653495952486992, 0.006356395315378904, 0.0032207071781158447,
    0.0014958956744521856, 0.0006245493423193693, 0.00022806067136116326, 7.001897029113024e-05,
    1.700967004580889e-05, 2.9508453280868707e-06, 2.991148448927561e-07, 1.0561630681138467e-08,
    2.0839590903626304e-12,
    1.2080016136169434, 1.2080016136169434, 1.2544336318969727, 1.2166270017623901,
    1.1409283876419067, 1.0481040477752686, 0.9487869143486023, 0.848827064037323,
    0.7515726089477539, 0.6589786410331726, 0.5721888542175293, 0.49185675382614136,
    0.4183269739151001, 0.351739764213562, 0.29209065437316895, 0.23926487565040588,
    0.1930568814277649, 0.15318241715431213, 0.11928722262382507, 0.09095495194196701,
    0.0677160695195198, 0.049058571457862854, 0.034440796822309494, 0.02331077866256237,
    0.01513729989528656, 0.009345472790300846, 0.005413878709077835, 0.0028882967308163643,
    0.0013792006066069007, 0.0005620715674012899, 0.00017833866877481341, 3.495463897706941e-05,
    1.0091271178680472e-06,
    0.9743183255195618, 0.9743183255195618, 1.0233978033065796, 1.0063749551773071,
    0.9590181112289429, 0.8971729874610901, 0.8288960456848145, 0.7586027383804321,
    0.6888168454170227, 0.6210151314735413, 0.5560718178749084, 0.4945049285888672,
    0.4366181194782257, 0.3825838267803192, 0.33249157667160034, 0.28637632727622986,
    0.24423392117023468, 0.20602887868881226, 0.17169778048992157, 0.14114992320537567,
    0.11426694691181183, 0.09090207517147064, 0.07087995857000351, 0.054010841995477676,
    0.04015349969267845, 0.0289692971855402, 0.020118942484259605, 0.013298016972839832,
    0.008223931305110455, 0.004627220332622528, 0.0022467554081231356, 0.0008285764488391578,
    0.00012794962094631046,
    0.8507804870605469, 0.8507804870605469, 0.9009188413619995, 0.8940852880477905,
    0.8608383536338806, 0.8146451711654663, 0.762319028377533, 0.707577645778656,
    0.6525347828865051, 0.5984179973602295, 0.545945942401886, 0.4955383539199829,
    0.44743815064430237, 0.40178364515304565, 0.3586520254611969, 0.31808528304100037,
    0.28010547161102295, 0.24472272396087646, 0.2119392603635788, 0.18175025284290314,
    0.15414312481880188, 0.12909571826457977, 0.10657412558794022, 0.08655504882335663,
    0.069154292345047, 0.05416407063603401, 0.04135175421833992, 0.03053196519613266,
    0.021551376208662987, 0.014275805093348026, 0.008579213172197342, 0.004334412049502134,
    0.0014050627360120416,
    0.7843322157859802, 0.7843322157859802, 0.835751473903656, 0.8349137306213379,
    0.8096798658370972, 0.7723215818405151, 0.7290308475494385, 0.6831750273704529,
    0.6366593837738037, 0.5905812382698059, 0.5455734133720398, 0.5019962787628174,
    0.46004948019981384, 0.41983866691589355, 0.38141635060310364, 0.34480682015419006,
    0.3100212812423706, 0.2770666480064392, 0.24595017731189728, 0.21668151021003723,
    0.1892726719379425, 0.1637369990348816, 0.14008711278438568, 0.11836898326873779,
    0.09886974096298218, 0.0814344733953476, 0.06585594266653061, 0.051986079663038254,
    0.039723072201013565, 0.02900012768805027, 0.019775068387389183, 0.01202020887285471,
    0.005709603428840637,
    0.7521430253982544, 0.7521430253982544, 0.8053659200668335, 0.808547854423523,
    0.7882316708564758, 0.7561438679695129, 0.7181963920593262, 0.6775973439216614,
    0.6361545324325562, 0.594901442527771, 0.5544260740280151, 0.5150545239448547,
    0.476958304643631, 0.44021859765052795, 0.40486612915992737, 0.37090563774108887,
    0.33833110332489014, 0.3071350157260895, 0.2773137390613556, 0.24887020885944366,
    0.2218145728111267, 0.19616390764713287, 0.17194077372550964, 0.1492185890674591,
    0.12841102480888367, 0.10938040912151337, 0.0919058695435524, 0.07583107799291611,
    0.06105346232652664, 0.04751504585146904, 0.035193875432014465, 0.02409513294696808,
    0.01423478964716196,
    0.7426434755325317, 0.7426434755325317, 0.7981261610984802, 0.8042436838150024,
    0.7870522737503052, 0.7581304907798767, 0.7233180403709412, 0.6857792139053345,
    0.6472915410995483, 0.6088645458221436, 0.5710657835006714, 0.5342022180557251,
    0.4984271228313446, 0.4638036787509918, 0.430344820022583, 0.3980379104614258,
    0.3668602705001831, 0.3367888033390045, 0.3078058660030365, 0.2799023687839508,
    0.25307902693748474, 0.22734642028808594, 0.20272399485111237, 0.1792958825826645,
    0.1575765162706375, 0.13743168115615845, 0.11861400306224823, 0.10094260424375534,
    0.08429338037967682, 0.06859114021062851, 0.05380238965153694, 0.03992772474884987,
    0.026982024312019348,
    0.7490480542182922, 0.7490480542182922, 0.807063639163971, 0.8154112100601196,
    0.8001798987388611, 0.7730544209480286, 0.7399354577064514, 0.7040172815322876,
    0.6670886874198914, 0.6301599144935608, 0.5937923789024353, 0.558283269405365,
    0.5237730741500854, 0.490310937166214, 0.4578949511051178, 0.4264972507953644,
    0.3960801959037781, 0.36660635471343994, 0.3380446434020996, 0.31037387251853943,
    0.2835842967033386, 0.25767794251441956, 0.2326676845550537, 0.20864221453666687,
    0.1861988753080368, 0.16520237922668457, 0.1453782021999359, 0.12651948630809784,
    0.10847786068916321, 0.09115618467330933, 0.07450219243764877, 0.05850228667259216,
    0.043159693479537964,
    0.7666383981704712, 0.7666383981704712, 0.8272296190261841, 0.8372570276260376,
    0.8231531977653503, 0.7968683838844299, 0.764447808265686, 0.7291609644889832,
    0.6928334832191467, 0.6564904451370239, 0.6206955909729004, 0.5857406258583069,
    0.5517565011978149, 0.5187803506851196, 0.486797034740448, 0.4557650089263916,
    0.4256332218647003, 0.3963513970375061, 0.36787664890289307, 0.34017711877822876,
    0.31323373317718506, 0.28704074025154114, 0.26160478591918945, 0.23701722919940948,
    0.2139434516429901, 0.19224593043327332, 0.17162708938121796, 0.1518586277961731,
    0.13277257978916168, 0.11425452679395676, 0.09623778611421585, 0.07869896292686462,
    0.06163669750094414,
    0.7914106249809265, 0.7914106249809265, 0.8543756008148193, 0.8655934929847717,
    0.8519905805587769, 0.8258668184280396, 0.7934560179710388, 0.7581266760826111,
    0.7217538356781006, 0.685384213924408, 0.6495871543884277, 0.6146509647369385,
    0.5806981921195984, 0.54775470495224, 0.5157929062843323, 0.48475882411003113,
    0.4545890986919403, 0.4252221882343292, 0.39660489559173584, 0.3686964511871338,
    0.34147024154663086, 0.3149142563343048, 0.2890302836894989, 0.2639119625091553,
    0.24027906358242035, 0.21799199283123016, 0.19673526287078857, 0.17626507580280304,
    0.1564004272222519, 0.1370164155960083, 0.1180390790104866, 0.09944305568933487,
    0.08123350143432617,
    0.8193092942237854, 0.8193092942237854, 0.8842186331748962, 0.8961772322654724,
    0.8826193809509277, 0.8562114238739014, 0.8233845233917236, 0.7876102924346924,
    0.75081467628479, 0.7140666246414185, 0.6779410243034363, 0.6427229046821594,
    0.6085262298583984, 0.5753660798072815, 0.5432030558586121, 0.5119713544845581,
    0.4815967381000519, 0.45200756192207336, 0.4231419265270233, 0.3949516713619232,
    0.3674042522907257, 0.3404829204082489, 0.3141860365867615, 0.2886093258857727,
    0.2645144462585449, 0.2417602390050888, 0.2200184017419815, 0.19903497397899628,
    0.17862145602703094, 0.15864819288253784, 0.1390397697687149, 0.11977481842041016,
    0.10087322443723679,
    0.845791220664978, 0.845791220664978, 0.9120382070541382, 0.924354076385498,
    0.910575807094574, 0.8836870193481445, 0.8502907156944275, 0.8139469027519226,
    0.7766244411468506, 0.7394093871116638, 0.7028798460960388, 0.667316198348999,
    0.6328237056732178, 0.5994069576263428, 0.5670157074928284, 0.535573422908783,
    0.504996120929718, 0.47520360350608826, 0.4461265504360199, 0.4177108705043793,
    0.3899192810058594, 0.3627314865589142, 0.3361433148384094, 0.3102521598339081,
    0.28585100173950195, 0.26279789209365845, 0.24075593054294586, 0.21946512162685394,
    0.19873327016830444, 0.17842957377433777, 0.15848031640052795, 0.1388709992170334,
    0.11964000016450882,
    0.8656730055809021, 0.8656730055809021, 0.9325481057167053, 0.9449565410614014,
    0.9309282898902893, 0.9036502838134766, 0.8698374032974243, 0.8331059217453003,
    0.7954497933387756, 0.7579632997512817, 0.7212232351303101, 0.6855038404464722,
    0.6509018540382385, 0.6174124479293823, 0.5849758982658386, 0.5535069108009338,
    0.52291339635849, 0.49310803413391113, 0.46401581168174744, 0.4355776607990265,
    0.40775251388549805, 0.3805173337459564, 0.3538658022880554, 0.3278963267803192,
    0.3034248352050781, 0.2803100347518921, 0.25820979475975037, 0.2368607521057129,
    0.21606917679309845, 0.19570444524288177, 0.175695538520813, 0.15603511035442352,
    0.13678015768527985,
    0.8733053803443909, 0.8733053803443909, 0.9400642514228821, 0.9524664282798767,
    0.9384329915046692, 0.9111778736114502, 0.8774345517158508, 0.8408258557319641,
    0.8033450841903687, 0.7660817503929138, 0.7296061515808105, 0.6941850185394287,
    0.6599076986312866, 0.6267620325088501, 0.5946815013885498, 0.5635746121406555,
    0.5333435535430908, 0.5038960576057434, 0.47515273094177246, 0.4470508098602295,
    0.4195461869239807, 0.3926132023334503, 0.36624351143836975, 0.3405357301235199,
    0.31632331013679504, 0.29346731305122375, 0.27162328362464905, 0.2505260407924652,
    0.22998087108135223, 0.2098572552204132, 0.19008605182170868, 0.17066580057144165,
    0.1516699492931366,
    0.8631329536437988, 0.8631329536437988, 0.9290103316307068, 0.9414708614349365,
    0.9279425144195557, 0.9014304280281067, 0.8685616254806519, 0.832899808883667,
    0.7964038848876953, 0.7601426839828491, 0.7246737480163574, 0.6902555823326111,
    0.6569722294807434, 0.624807596206665, 0.5936921238899231, 0.5635316967964172,
    0.5342260599136353, 0.5056804418563843, 0.4778129458427429, 0.45055821537971497,
    0.4238695800304413, 0.3977188467979431, 0.3720953166484833, 0.34709689021110535,
    0.3235715329647064, 0.30138540267944336, 0.2801940441131592, 0.25973132252693176,
    0.2398010492324829, 0.22027145326137543, 0.2010732889175415, 0.18220867216587067,
    0.16376397013664246);
// END sheen albedo table

float gltf_sheen_distribution(float tan2, float alpha_g)
{
    float sin2h = tan2 / (1.0 + tan2);
    float inv_r = alpha_g > 0.0 ? 1.0 / alpha_g : 0.0;
    float d = (2.0 + inv_r) * pow(sin2h, 0.5 * inv_r) * (0.5 * GLTF_PBR_INV_PI);
    return alpha_g > 0.0 ? d : 0.0;
}

float gltf_sheen_l(float x, float alpha_g)
{
    float t = (1.0 - alpha_g) * (1.0 - alpha_g);
    float a = mix(21.5473, 25.3245, t);
    float b = mix(3.82987, 3.32435, t);
    float c = mix(0.19823, 0.16801, t);
    float d = mix(-1.97760, -1.27393, t);
    float e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

float gltf_sheen_lambda(float cos_theta, float alpha_g)
{
    float x = abs(cos_theta);
    return x < 0.5 ? exp(gltf_sheen_l(x, alpha_g))
                   : exp(2.0 * gltf_sheen_l(0.5, alpha_g) - gltf_sheen_l(1.0 - x, alpha_g));
}

float gltf_sheen_albedo(float cos_theta, float sheen_roughness)
{
    float u = sqrt(clamp(cos_theta, 0.0, 1.0)) * 32.0;
    float w = clamp(sheen_roughness, 0.0, 1.0) * 16.0;
    int i = min(int(u), 31);
    int j = min(int(w), 15);
    float s = u - float(i);
    float t = w - float(j);
    float low = mix(GLTF_SHEEN_E[j * 33 + i], GLTF_SHEEN_E[j * 33 + i + 1], s);
    float high = mix(GLTF_SHEEN_E[j * 33 + 33 + i], GLTF_SHEEN_E[j * 33 + 34 + i], s);
    return mix(low, high, t);
}

float gltf_sheen_scaling(float n_dot_v, float n_dot_l)
{
    vec3 sc = u_gltf_pbr_sheen_color;
    float sc_max = max(sc.r, max(sc.g, sc.b));
    return max(min(1.0 - sc_max * gltf_sheen_albedo(n_dot_v, u_gltf_pbr_sheen_roughness),
                   1.0 - sc_max * gltf_sheen_albedo(n_dot_l, u_gltf_pbr_sheen_roughness)), 0.0);
}
#endif

#if defined(GLTF_PBR_TRANSMISSION) || defined(GLTF_PBR_DIFFUSE_TRANSMISSION)  // the dielectric's F and the layers'
// keep over the light let through (formulas: transmission_thin.glsl's header; read there and below)
vec3 gltf_transmission_fresnel(float ior, float c)
{
    float r = (ior - 1.0) / (ior + 1.0);
#if defined(GLTF_PBR_SPECULAR)
    vec3 fresnel = u_gltf_pbr_specular * fresnel_schlick(min(r * r * u_gltf_pbr_specular_color, vec3(1.0)), c);
#else
    vec3 fresnel = fresnel_schlick(vec3(r * r), c);
#endif
#if defined(GLTF_PBR_IRIDESCENCE)  // KHR_materials_iridescence: F' = mix(F, F_iridescence(film_f0), iridescence)
#if defined(GLTF_PBR_SPECULAR)
    vec3 film_f0 = min(r * r * u_gltf_pbr_specular_color, vec3(1.0)) * u_gltf_pbr_specular;
#else
    vec3 film_f0 = vec3(r * r);
#endif
    float thickness = mix(u_gltf_pbr_iridescence_thickness_minimum, u_gltf_pbr_iridescence_thickness_maximum,
                          u_gltf_pbr_iridescence_thickness_mix);
    vec3 film = gltf_iridescence_fresnel(1.0, u_gltf_pbr_iridescence_ior, film_f0, thickness, clamp(c, 0.0, 1.0));
    fresnel = mix(fresnel, film, u_gltf_pbr_iridescence);
#endif
    return fresnel;
}

float gltf_transmission_layers(ShadingFrame f, vec3 wo, float n_dot_v, float n_dot_l)
{
    float keep = 1.0;
#if defined(GLTF_PBR_SHEEN)
    keep = gltf_sheen_scaling(n_dot_v, n_dot_l);
#endif
#if defined(GLTF_PBR_CLEARCOAT_NORMAL)  // the coat's own normal n_c (gltf_pbr.glsl's gltf_clearcoat_normal)
    keep *= 1.0 - u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(max(dot(gltf_clearcoat_normal(f), wo), 0.0));
#elif defined(GLTF_PBR_CLEARCOAT)
    keep *= 1.0 - u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_v);
#endif
    return keep;
}
#endif

#if defined(GLTF_PBR_DIFFUSE_TRANSMISSION)  // KHR_materials_diffuse_transmission: the diffuse BTDF of a light behind
vec3 gltf_diffuse_transmission_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    vec3 mirrored = wi + (2.0 * n_dot_l) * f.n;
    float n_dot_v, n_dot_h, v_dot_h, tan2;
    bool valid = microfacet_geometry(f.n, mirrored, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, tan2);
    vec3 fresnel = gltf_transmission_fresnel(u_gltf_pbr_ior, v_dot_h);  // with KHR_materials_specular: its F
    float fresnel_max = max(fresnel.r, max(fresnel.g, fresnel.b));
#if defined(GLTF_PBR_TRANSMISSION)
    float t = u_gltf_pbr_transmission;
#else
    float t = 0.0;
#endif
    float scale = (1.0 - u_gltf_pbr_metallic) * (1.0 - t) * u_gltf_pbr_diffuse_transmission;
    vec3 value = u_gltf_pbr_diffuse_transmission_color * ((scale * GLTF_PBR_INV_PI) * (1.0 - fresnel_max) * n_dot_l);
    return valid ? value * gltf_transmission_layers(f, wo, n_dot_v, n_dot_l) : vec3(0.0);
}
#endif

#if defined(GLTF_PBR_VOLUME)  // KHR_materials_volume, _dispersion: their parameters, read by transmission_thin.glsl
float gltf_pbr_thickness() { return u_gltf_pbr_thickness; }
vec4 gltf_pbr_attenuation() { return vec4(u_gltf_pbr_attenuation_color, u_gltf_pbr_attenuation_distance); }
float gltf_pbr_dispersion() { return u_gltf_pbr_dispersion; }
#endif

vec3 gltf_pbr_response(ShadingFrame f, vec3 wi, vec3 wo, float n_dot_l)
{
    float n_dot_v, n_dot_h, v_dot_h, tan2;
    bool valid = microfacet_geometry(f.n, wi, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, tan2);
    float alpha = u_gltf_pbr_roughness * u_gltf_pbr_roughness;
    float a2 = alpha * alpha;
#if defined(GLTF_PBR_ANISOTROPY)  // KHR_materials_anisotropy: the base's lobe in the rotated frame (reads f.t, f.b)
    vec3 aniso_t, aniso_b;
    gltf_anisotropy_frame(f.n, f.t, f.b, u_gltf_pbr_anisotropy_direction, u_gltf_pbr_anisotropy_rotation, aniso_t,
                          aniso_b);
    float specular = gltf_anisotropy_specular(aniso_t, aniso_b, wi, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, alpha,
                                              u_gltf_pbr_anisotropy_strength);
#else
    float specular = gltf_pbr_specular(a2, tan2, n_dot_l, n_dot_v);  // 0 for roughness 0 (a delta)
#endif
    float x1 = max(1.0 - v_dot_h, 0.0);                   // v.h = |l + v|/2 may round above 1
    float x = (x1 * x1) * (x1 * x1) * x1;
    vec3 c = u_gltf_pbr_base_color;
    float m = u_gltf_pbr_metallic;
    float r = (u_gltf_pbr_ior - 1.0) / (u_gltf_pbr_ior + 1.0);  // KHR_materials_ior: f0 = ((ior - 1)/(ior + 1))^2
    float f0 = r * r;
#if defined(GLTF_PBR_SPECULAR)  // KHR_materials_specular: an rgb F_d, the diffuse weighted by 1 - max(F_d)
    vec3 fd = gltf_specular_fresnel(f0, u_gltf_pbr_specular, u_gltf_pbr_specular_color, x);
    float fd_max = max(fd.r, max(fd.g, fd.b));
#else
    float fd = f0 + (1.0 - f0) * x;
    float fd_max = fd;
#endif
    vec3 fresnel = fd * (1.0 - m) + (c + (1.0 - c) * x) * m;
#if defined(GLTF_PBR_IRIDESCENCE)  // KHR_materials_iridescence: F = mix(F, F_iridescence, iridescence) (gltf_iridescence.glsl)
#if defined(GLTF_PBR_SPECULAR)
    vec3 film_f0 = gltf_specular_fresnel(f0, u_gltf_pbr_specular, u_gltf_pbr_specular_color, 0.0);
#else
    vec3 film_f0 = vec3(f0);
#endif
    gltf_iridescence_parts(c, m, x, film_f0, vec3(fd), v_dot_h, fd_max, fresnel);
#endif
    // mix(dielectric, metal, m) = (c/pi)(n.l)(1 - fd)(1 - m) + [fd (1 - m) + (c + (1 - c) x) m] V D (n.l)
    vec3 diffuse = (c * (GLTF_PBR_INV_PI * n_dot_l)) * (1.0 - fd_max) * (1.0 - m);
#if defined(GLTF_PBR_TRANSMISSION)  // KHR_materials_transmission: the diffuse weighted by 1 - t (transmission_thin.glsl)
    diffuse *= 1.0 - u_gltf_pbr_transmission;
#endif
#if defined(GLTF_PBR_DIFFUSE_TRANSMISSION)  // KHR_materials_diffuse_transmission: the diffuse weighted by 1 - dt
    diffuse *= 1.0 - u_gltf_pbr_diffuse_transmission;
#endif
    vec3 value = diffuse + fresnel * specular;
#if defined(GLTF_PBR_SHEEN)  // KHR_materials_sheen: sheen_color D V + f_r scaling, times n.l
    float alpha_g = u_gltf_pbr_sheen_roughness * u_gltf_pbr_sheen_roughness;
    vec3 sc = u_gltf_pbr_sheen_color;
    float scaling = gltf_sheen_scaling(n_dot_v, n_dot_l);
    float sheen_v_cos = 1.0 / ((1.0 + gltf_sheen_lambda(n_dot_v, alpha_g) + gltf_sheen_lambda(n_dot_l, alpha_g))
                               * (4.0 * n_dot_v));
    float sheen = min(gltf_sheen_distribution(tan2, alpha_g) * sheen_v_cos, FLT_MAX);
    value = value * scaling + sc * sheen;
#endif
#if defined(GLTF_PBR_CLEARCOAT)  // KHR_materials_clearcoat: mix(f_r, V_c D_c, clearcoat F_c(n.v)), times n.l
    float alpha_c = u_gltf_pbr_clearcoat_roughness * u_gltf_pbr_clearcoat_roughness;
    float a2_c = alpha_c * alpha_c;
#if defined(GLTF_PBR_CLEARCOAT_NORMAL)  // clearcoatNormalTexture: the coat's own normal on the unperturbed frame
    vec3 n_c = gltf_clearcoat_normal(f);
    float c_n_dot_l = dot(n_c, wi);
    float c_n_dot_v, c_n_dot_h, c_v_dot_h, c_tan2;
    bool c_valid = microfacet_geometry(n_c, wi, wo, c_n_dot_l, c_n_dot_v, c_n_dot_h, c_v_dot_h, c_tan2);
    float coat = c_valid ? gltf_pbr_specular(a2_c, c_tan2, c_n_dot_l, c_n_dot_v) : 0.0;  // times n_c.l
    float coat_weight = u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(max(dot(n_c, wo), 0.0));
#else
    float coat = gltf_pbr_specular(a2_c, tan2, n_dot_l, n_dot_v);  // the base's lobe; 0 for roughness 0 (a delta)
    float coat_weight = u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_v);
#endif
    value = value * (1.0 - coat_weight) + coat_weight * coat;
#endif
    return valid ? value : vec3(0.0);
}
