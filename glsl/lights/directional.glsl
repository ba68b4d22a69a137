// lights/directional.glsl -- a light at infinity (docs/design.md section 11; glphong/lights/directional.py).
//
// directional_incident(x, j, out wi, out E) -> true
//   wi = the unit vector toward the light (the host negates the direction of travel);  E [W/m^2] constant.

bool directional_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)
{
    wi = u_directional_towards[j];
    irradiance = u_directional_irradiance[j];
    return true;
}
