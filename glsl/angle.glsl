// angle.glsl -- accurate angles from a sine and a cosine (library chunk; docs/design.md section 3).
//
// atan2_first_quadrant(y, x) -> atan(y / x) [rad] in [0, pi/2] for y, x >= 0; 0 where both are 0.
//   Cephes' atanf polynomial (S. L. Moshier, Cephes Math Library) after reduction to |t| <= tan(pi/8)
//   by selects, good to 3 ulp (measured).  GLSL's atan(y, x) may err by 4096 ulp (GLSL 4.50, 4.7.1);
//   llvmpipe's measured 3.3e-6 absolute, 2e-5 relative.  With y = |w - (n.w) n| (the part across n)
//   and x = n.w it is the polar angle of w, accurate also where acos(n.w) resolves nothing
//   (below 3.5e-4 rad in float32).
// Dimensionless inputs of the same scale (a sine and a cosine, or two lengths); no branch.

float atan2_first_quadrant(float y, float x)
{
    float lo = min(y, x);
    float hi = max(y, x);
    float r = hi > 0.0 ? lo / hi : 0.0;                   // in [0, 1]
    bool mid = r > 0.41421356237309503;                   // tan(pi/8)
    float t = mid ? (r - 1.0) / (r + 1.0) : r;            // |t| <= tan(pi/8)
    float z = t * t;
    float p = (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * t + t;
    float a = (mid ? 0.78539816339744831 : 0.0) + p;      // atan(r) in [0, pi/4]
    return y > x ? 1.5707963267948966 - a : a;
}
