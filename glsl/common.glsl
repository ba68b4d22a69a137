// common.glsl -- numeric helpers shared by every chunk (DESIGN section 3).
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


bool safe_normalize(vec3 x, out vec3 x_hat, out float len)
{
    float s = max(max(abs(x.x), abs(x.y)), abs(x.z));
    if (isnan(x.x + x.y + x.z) || isinf(s) || !(s > 0.0)) {
        x_hat = vec3(0.0);
        len = 0.0;
        return false;
    }
    vec3 y = x / s;
    float yy = dot(y, y);
    len = s * sqrt(yy);
    x_hat = y * inversesqrt(yy);
    return true;
}
