// lights/sphere.glsl -- a uniform spherical light (docs/design.md section 13; glphong/lights/sphere.py).
//
// Centre c_j, radius R_j, radiance L_j [W/(m^2 sr)] leaving its surface: seen from x at distance d > R it is the
// cone of directions of half-angle sigma about w_c = (c - x)/d, sin^2(sigma) = (R/d)^2, of uniform radiance L.
// sphere_irradiance(x, n, j) = L_j F(cos theta, sin^2 sigma), cos theta = n.w_c: the cone's exact integral of (n.w)^+
//   (Snyder 1996; Lagarde and de Rousiers 2014), the horizon included:
//   cos^2 theta >= sin^2 sigma:  F = pi sin^2(sigma) max(cos theta, 0)
//   else:  X = sqrt(1/sin^2 sigma - 1) = cot sigma,  y = -X cos(theta)/sin(theta),  s = sin(theta) sqrt(1 - y^2),
//          F = (cos(theta) acos(y) - X s) sin^2(sigma) + atan(s / X)
//   with acos and atan by the 3-ulp polynomial (area_angle, atan2_first_quadrant); 0 where d <= R (x inside).
// sphere_sample(x, n, j, k, wi, E): cell k = (a, b) of m x m (m = u_sphere_samples[j]) of the cone, equal solid
//   angles: cos(t) = 1 - (a + 1/2)/m (1 - cos sigma), phi = 2 pi (b + 1/2)/m about w_c;
//   E = L_j 2 pi (1 - cos sigma) / m^2  (the midpoint rule in solid angle); 1 - cos sigma = sin^2 sigma / (1 + cos sigma).
// Key defines read here: none (SPHERE_MAX_SAMPLES bounds the generated loop).

vec3 sphere_irradiance(vec3 x, vec3 n, int j)
{
    vec3 wc;
    float d;
    bool valid = safe_normalize(u_sphere_center[j] - x, wc, d);
    float ratio = u_sphere_radius[j] / d;
    float s2 = ratio * ratio;                                   // sin^2 sigma
    float c = dot(n, wc);
    float st = sqrt(max(1.0 - c * c, 0.0));
    float f;
    if (c * c >= s2) {
        f = 3.14159265358979 * s2 * max(c, 0.0);
    } else {
        float X = sqrt(max(1.0 / s2 - 1.0, 0.0));
        float y = clamp(-X * c / max(st, 1e-30), -1.0, 1.0);
        float s = st * sqrt(max(1.0 - y * y, 0.0));
        f = (c * area_angle(sqrt(max(1.0 - y * y, 0.0)), y) - X * s) * s2 + atan2_first_quadrant(s, X);
    }
    return valid && ratio < 1.0 ? u_sphere_radiance[j] * max(f, 0.0) : vec3(0.0);
}

bool sphere_sample(vec3 x, vec3 n, int j, int k, out vec3 wi, out vec3 irradiance)
{
    int m = int(u_sphere_samples[j]);
    int a = k / m;
    int b = k - a * m;
    vec3 wc;
    float d;
    bool valid = safe_normalize(u_sphere_center[j] - x, wc, d);
    float ratio = u_sphere_radius[j] / d;
    float s2 = ratio * ratio;
    float versine = s2 / (1.0 + sqrt(max(1.0 - s2, 0.0)));      // 1 - cos sigma, without cancelling
    float v = (float(a) + 0.5) / float(m) * versine;            // 1 - cos t
    float st = sqrt(max(v * (2.0 - v), 0.0));                   // sin t
    float phi = 6.28318530717959 * (float(b) + 0.5) / float(m);
    vec3 e1 = normalize(abs(wc.x) < 0.9 ? cross(wc, vec3(1.0, 0.0, 0.0)) : cross(wc, vec3(0.0, 1.0, 0.0)));
    vec3 e2 = cross(wc, e1);
    wi = wc * (1.0 - v) + (e1 * cos(phi) + e2 * sin(phi)) * st;
    irradiance = u_sphere_radiance[j] * (6.28318530717959 * versine / float(m * m));
    return valid && ratio < 1.0 && k < m * m;
}
