// lights/disk.glsl -- a one-sided uniform disk light (docs/design.md section 13; glphong/lights/disk.py).
//
// Centre C_j, unit normal N_j (the side it emits to), radius R_j, radiance L_j [W/(m^2 sr)].  Relative to x,
// c = C - x; the rim is p(t) = c + R (cos t e1 + sin t e2), e1 x e2 = N, counter-clockwise seen from the front.
// disk_irradiance(x, n, j) = L_j max(-(1/2) (I_arc + chord), 0): Lambert's contour integral -(1/2) oint n.(p x dp)/|p|^2
//   over the rim (clipped to the horizon n.p >= 0: an arc and the chord along the horizon, whose edge term is
//   Lambert's Theta (n.m)).  On the rim n.(p x p')/|p|^2 = (a cos tau + b sin tau + g)/(A + rho cos tau), tau from
//   the rim's farthest point, A = |c|^2 + R^2, rho = 2R |c_in-plane|, g = R^2 n.N; with s = sqrt((A - rho)(A + rho)),
//   k = (A - rho)/s and an end of the arc at (X, Y) = (cos tau, sin tau):
//     J = int dtau/(A + rho cos tau) = (2/s) [atan2(k Y, 1 + X)]  (+ 2 pi / s past tau = pi),
//     K = int cos/(...) = -dtau rho/(s (s + A)) - (2A/s) [D]/rho,  D = atan2((k - 1)(1 + X) Y, (1 + X)^2 + k Y^2)
//       (the angle between the half-angle vectors: no cancellation as rho -> 0),
//     Lsin = int sin/(...) = -(1/rho) log1p(rho w) = -w log1p(rho w)/(rho w),  w = (X1 - X0)/(A + rho X0),
//   and over the whole rim J = 2 pi/s, K = -2 pi rho/(s (s + A)), Lsin = 0.  No sin or cos: angles by atan2
//   (area_angle, 3 ulp), half angles by the bisector (1 + X, Y).  0 where x is not in front ((x - C).N <= 0).
// disk_sample(x, n, j, k, wi, E): cell k = (a, b) of m x m of equal area pi R^2 / m^2, radius R sqrt((a + 1/2)/m),
//   angle 2 pi (b + 1/2)/m: E = L_j cos_l (pi R^2 / m^2) / d^2 (the midpoint rule).
// Key defines read here: none (DISK_MAX_SAMPLES bounds the generated loop).

float disk_atan2(float y, float x)
{
    return y >= 0.0 ? area_angle(y, x) : -area_angle(-y, x);
}

float disk_log1p_over(float z)            // log(1 + z) / z, 1 at z = 0 (Kahan: exact where 1 + z rounds)
{
    float u = 1.0 + z;
    return u == 1.0 ? 1.0 : log(u) / (u - 1.0);
}

float disk_angle_over(float y, float x)   // atan2(y, x) / y, 1/x at y = 0 (x > 0)
{
    return y != 0.0 ? disk_atan2(y, x) / y : 1.0 / x;
}

vec3 disk_irradiance(vec3 x, vec3 n, int j)
{
    vec3 N = normalize(u_disk_normal[j]);                          // as the twin: the rim a circle, e1, e2 unit
    float R = u_disk_radius[j];
    vec3 c = u_disk_center[j] - x;
    vec3 e1 = normalize(abs(N.x) < 0.9 ? cross(N, vec3(1.0, 0.0, 0.0)) : cross(N, vec3(0.0, 1.0, 0.0)));
    vec3 e2 = cross(N, e1);
    vec2 cp = vec2(dot(c, e1), dot(c, e2));
    float A = dot(c, c) + R * R;
    float rho = 2.0 * R * length(cp);
    vec2 g = rho > 0.0 ? cp / length(cp) : vec2(1.0, 0.0);       // the rim's farthest point from x, in (e1, e2)
    vec2 gp = vec2(-g.y, g.x);
    float alpha = R * dot(n, cross(c, e2));
    float beta = -R * dot(n, cross(c, e1));
    float a = alpha * g.x + beta * g.y;
    float b = beta * g.x - alpha * g.y;
    float gam = R * R * dot(n, N);
    float s = sqrt(max((A - rho) * (A + rho), 0.0));
    float k = (A - rho) / s;
    float km1 = -rho * (s + A - rho) / (s * (s + A));              // k - 1, without cancelling
    // the horizon: n.p(t) = n.c + kappa cos(t - psi)
    vec2 np = vec2(dot(n, e1), dot(n, e2));
    float kappa = R * length(np);
    float h = dot(n, c);
    float I;
    float chord = 0.0;
    if (h >= kappa) {                                              // the whole disk above the horizon
        I = a * (-6.28318530717959 * rho / (s * (s + A))) + gam * (6.28318530717959 / s);
    } else {
        float cb = clamp(-h / kappa, -1.0, 1.0);
        float sb = sqrt(max(1.0 - cb * cb, 0.0));
        vec2 nh = np / length(np);
        vec2 nq = vec2(-nh.y, nh.x);
        vec2 u0 = cb * nh - sb * nq;                               // the arc, counter-clockwise from u0 to u1
        vec2 u1 = cb * nh + sb * nq;
        float X0 = dot(u0, g);
        float Y0 = dot(u0, gp);
        float X1 = dot(u1, g);
        float Y1 = dot(u1, gp);
        float t0 = disk_atan2(Y0, X0);
        float t1 = disk_atan2(Y1, X1);
        bool wraps = t1 < t0;                                      // through tau = pi, the rim's nearest point
        float dt = t1 - t0 + (wraps ? 6.28318530717959 : 0.0);
        float J = (2.0 / s) * (disk_atan2(k * Y1, 1.0 + X1) - disk_atan2(k * Y0, 1.0 + X0) + (wraps ? 3.14159265358979 : 0.0));
        float scale = -(s + A - rho) / (s * (s + A));              // (k - 1) / rho
        float D1 = disk_angle_over(km1 * (1.0 + X1) * Y1, (1.0 + X1) * (1.0 + X1) + k * Y1 * Y1) * scale * (1.0 + X1) * Y1;
        float D0 = disk_angle_over(km1 * (1.0 + X0) * Y0, (1.0 + X0) * (1.0 + X0) + k * Y0 * Y0) * scale * (1.0 + X0) * Y0;
        float K = -dt * rho / (s * (s + A)) - (2.0 * A / s) * (D1 - D0);
        float w = (X1 - X0) / (A + rho * X0);
        float L = -w * disk_log1p_over(rho * w);                   // -(1/rho) log1p(rho w), -w on the axis
        I = h > -kappa ? a * K + b * L + gam * J : 0.0;
        vec3 p0 = c + R * (u0.x * e1 + u0.y * e2);
        vec3 p1 = c + R * (u1.x * e1 + u1.y * e2);
        vec3 m = cross(p1, p0 - p1);                               // the chord, from the arc's end back to its start
        float lm = length(m);
        chord = h > -kappa && lm > 0.0 ? area_angle(lm, dot(p1, p0)) * (dot(n, m) / lm) : 0.0;
    }
    bool front = dot(x - u_disk_center[j], N) > 0.0;
    return front ? u_disk_radiance[j] * max(-0.5 * (I + chord), 0.0) : vec3(0.0);
}

bool disk_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)
{
    int m = int(u_disk_samples[j]);
    int a = k / m;
    int b = k - a * m;
    vec3 N = normalize(u_disk_normal[j]);                          // as the twin: the rim a circle, e1, e2 unit
    float R = u_disk_radius[j];
    vec3 e1 = normalize(abs(N.x) < 0.9 ? cross(N, vec3(1.0, 0.0, 0.0)) : cross(N, vec3(0.0, 1.0, 0.0)));
    vec3 e2 = cross(N, e1);
    float r = R * sqrt((float(a) + 0.5) / float(m));
    float phi = 6.28318530717959 * (float(b) + 0.5) / float(m);
    vec3 y = (u_disk_center[j] - x) + r * (cos(phi) * e1 + sin(phi) * e2);
    float d;
    bool valid = safe_normalize(y, wi, d);
    float cos_l = -dot(N, wi);
    irradiance = u_disk_radiance[j] * (((cos_l * (3.14159265358979 * R * R / float(m * m))) / d) / d);
    return valid && k < m * m && cos_l > 0.0;
}
