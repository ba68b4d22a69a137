// common.glsl -- numeric helpers and the shading frame shared by every chunk (docs/design.md sections 3, 8).
//
// safe_normalize(x, out x_hat, out len) -> valid
//   s = max_i |x_i|;  valid  <=>  no x_i is NaN or Inf, and s > 0   (false for zero, NaN, Inf)
//   Finiteness: isnan(x_0 + x_1 + x_2) catches any NaN component (and Inf - Inf), isinf(s) any
//   Inf; on llvmpipe max() drops a NaN operand and ordered comparisons with NaN (NaN <= FLT_MAX,
//   NaN == 0) evaluate to true, so neither s nor a comparison alone can be trusted.
//   y = x / s;  len = s * sqrt(y.y);  x_hat = y * inversesqrt(y.y)
//   (x / s, not x * (1 / s): 1 / s is subnormal, and flushed, for s > 1 / FLT_MIN ~ 8.5e37)
//   |x|^2 is never formed from raw coordinates, so lengths from FLT_MIN to FLT_MAX (float32)
//   neither underflow nor overflow.  On failure x_hat = 0 and len = 0.
//   Units: len has the units of x; x_hat is dimensionless.
//   NAIVE (the textbook formulation, for the stability report only): plain_normalize.
// plain_normalize(x, out x_hat, out len) -> true
//   x_hat = normalize(x), len = length(x): the textbook arithmetic, forming |x|^2 from the raw coordinates.
//   Compiled at a site in place of safe_normalize only where the program key proves it (numerics='auto',
//   docs/design.md section 3, "Stability where a scene needs it"): |x|^2 within [FLT_MIN / eps, FLT_MAX / 4]
//   at every point the site can see, so that nothing under- or overflows and x is never zero.  Sites and
//   their defines: the normal in mesh_fragment.glsl (NAIVE_NORMAL), the view vector in shade.glsl
//   (NAIVE_VIEW), a point, spot or unattenuated light's direction in lights/*.glsl (NAIVE_LIGHT).
//
// ShadingFrame: the local frame a material's response reads (docs/design.md section 8):
//   n the unit normal; t, b the unit tangent and bitangent (0 unless HAS_TANGENT); uv (0 unless HAS_UV).
// frame_from_tangent(n, tangent, out t, out b)
//   t = normalize(tangent.xyz - (n . tangent.xyz) n)   (Gram-Schmidt against the shading normal);
//   b = sign(tangent.w) cross(n, t)                     (w < 0: mirrored texture space);
//   where the projection is zero or not finite, or the tangent is parallel to n (its part across n
//   at most FRAME_PARALLEL_LIMIT = 2^-10 times its part along n: there the projection is rounding
//   noise, about as long as n's own), t is the tangent of the branchless orthonormal basis of
//   Duff et al. 2017 ("Building an orthonormal basis, revisited") around n.
// shading_frame(n, tangent, uv) -> the ShadingFrame of a shading point (t, b only when HAS_TANGENT).
// Key defines read here: NAIVE, HAS_TANGENT.
//   (NAIVE_NORMAL, NAIVE_VIEW, NAIVE_LIGHT choose plain_normalize at their sites, see above.)

const float FLT_MAX = 3.402823466e38;
const float FRAME_PARALLEL_LIMIT = 0.0009765625;  // 2^-10: frame_from_tangent's test for a tangent along n

bool plain_normalize(vec3 x, out vec3 x_hat, out float len)
{
    x_hat = normalize(x);
    len = length(x);
    return true;
}

#if NAIVE
bool safe_normalize(vec3 x, out vec3 x_hat, out float len)
{
    return plain_normalize(x, x_hat, len);
}
#else
bool safe_normalize(vec3 x, out vec3 x_hat, out float len)
{
    float s = max(max(abs(x.x), abs(x.y)), abs(x.z));
    bool valid = !(isnan(x.x + x.y + x.z) || isinf(s) || !(s > 0.0));
    vec3 y = x / (valid ? s : 1.0);
    float yy = dot(y, y);
    len = valid ? s * sqrt(yy) : 0.0;
    x_hat = valid ? y * inversesqrt(yy) : vec3(0.0);
    return valid;
}
#endif

struct ShadingFrame {
    vec3 n;    // unit normal
    vec3 t;    // unit tangent
    vec3 b;    // unit bitangent
    vec2 uv;   // texture coordinates
};

void frame_from_tangent(vec3 n, vec4 tangent, out vec3 t, out vec3 b)
{
    float len;
    float along = dot(n, tangent.xyz);
    bool projected = safe_normalize(tangent.xyz - along * n, t, len);
    projected = projected && len > FRAME_PARALLEL_LIMIT * abs(along);
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    vec3 fallback = vec3(1.0 + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x);
    t = projected ? t : fallback;
    b = (tangent.w < 0.0 ? -1.0 : 1.0) * cross(n, t);
}

ShadingFrame shading_frame(vec3 n, vec4 tangent, vec2 uv)
{
    ShadingFrame f;
    f.n = n;
    f.t = vec3(0.0);
    f.b = vec3(0.0);
    f.uv = uv;
#if HAS_TANGENT
    frame_from_tangent(n, tangent, f.t, f.b);
#endif
    return f;
}
