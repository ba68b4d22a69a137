// shadow_fragment.glsl -- the shadow pass: each caster's distance from the light (docs/design.md section 12).
//
// out_distance = |x - o| (SHADOW_ORTHO 0: a cube face of a light at o) or a . (x - o) (SHADOW_ORTHO 1: an
// orthographic map along the unit direction of travel a, o on its near plane) [m], from the interpolated world
// position x of the fragment at the texel's centre.  The pass blends with MIN into a target cleared to FLT_MAX, so
// each texel keeps the nearest caster's distance exactly as computed here (no depth buffer, no depth precision).
// Key defines read here: SHADOW_ORTHO.

invariant in vec3 v_position;
uniform vec3 u_shadow_origin;
#if SHADOW_ORTHO
uniform vec3 u_shadow_axis;
#endif
layout(location = 0) out float out_distance;

void main()
{
#if SHADOW_ORTHO
    out_distance = dot(v_position - u_shadow_origin, u_shadow_axis);
#else
    vec3 direction;
    float d;
    bool valid = safe_normalize(v_position - u_shadow_origin, direction, d);
    out_distance = valid ? d : 0.0;
#endif
}
