// fresnel.glsl -- the Fresnel factors a glossy term can take (docs/design.md section 9), clamped and
// branchless, never NaN for a valid cosine or index.
//
// fresnel_schlick(f0, c) -> f0 + (1 - f0) (1 - c)^5            Schlick 1994, f0 in [0, 1] per channel
//   c is clamped to [0, 1] first: a cosine that rounds above 1 gives f0, not a negative power.
// fresnel_dielectric(ior, c) -> the exact unpolarised reflectance of a dielectric (Cook and Torrance 1982)
//   F = (g - c)^2 / (2 (g + c)^2) (1 + (c (g + c) - 1)^2 / (c (g - c) + 1)^2),  g^2 = ior^2 + c^2 - 1
//   g - c is formed as (ior^2 - 1) / (g + c) (no cancellation as ior -> 1); total internal reflection
//   (g^2 < 0) gives 1; c = 0 (grazing) gives 1; ior in (0, 1e6], c clamped to [0, 1].  Dimensionless.

vec3 fresnel_schlick(vec3 f0, float c)
{
    float m = clamp(1.0 - c, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (vec3(1.0) - f0) * (m2 * m2 * m);
}

float fresnel_dielectric(float ior, float c)
{
    c = clamp(c, 0.0, 1.0);
    float a = (ior - 1.0) * (ior + 1.0);
    float g2 = a + c * c;
    float g = sqrt(max(g2, 0.0));
    float g_plus_c = g + c;
    float safe = max(g_plus_c, 1e-30);
    float ratio = (a / safe) / safe;                  // (g - c) / (g + c)
    float g_minus_c = a / safe;
    float outer = c * g_plus_c - 1.0;
    float inner = c * g_minus_c + 1.0;
    float q = outer / inner;
    float f = 0.5 * (ratio * ratio) * (1.0 + q * q);
    return (g2 < 0.0 || g_plus_c <= 0.0) ? 1.0 : min(f, 1.0);
}
