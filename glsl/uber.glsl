// uber.glsl -- the uber-shader's run-time switches (only in programs keyed uber).
//
// uber_lobe(n, wi, wo, q) -> phong_lobe(...) if u_lobe_kind == 1, blinn_lobe(...) if 2, else 0
// Uniforms: u_use_ka, u_use_kd_la, u_use_diffuse (0 or 1, read through SWITCH()),
// u_lobe_kind, and the light counts u_{point,unattenuated,directional}_count (read through
// *_LIGHT_COUNT).  Specialised programs have none of this: glphong compiles the uber-shader
// only to measure what specialisation buys.

uniform float u_use_ka;
uniform float u_use_kd_la;
uniform float u_use_diffuse;
uniform float u_lobe_kind;
uniform float u_point_count;
uniform float u_unattenuated_count;
uniform float u_directional_count;

float uber_lobe(vec3 n, vec3 wi, vec3 wo, float q)
{
    if (u_lobe_kind == 1.0) {
        return phong_lobe(n, wi, wo, q);
    }
    if (u_lobe_kind == 2.0) {
        return blinn_lobe(n, wi, wo, q);
    }
    return 0.0;
}
