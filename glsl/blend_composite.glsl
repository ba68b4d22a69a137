// blend_composite.glsl -- the blended layers over the opaque image (glphong/gpu/peeling.py, docs/design.md section 16).
//
//   out = (C, A), the front-to-back composite of the layers, premultiplied (float32 RGBA, C [W/(m^2 sr)]);
//   the blend unit (ONE, ONE_MINUS_SRC_ALPHA) makes the target C + (1 - A) C_opaque: the "over" operator.
// Key defines read here: none.

uniform sampler2D u_layers;  // the accumulated layers, at the target's size
layout(location = 0) out vec4 out_color;

void main()
{
    out_color = texelFetch(u_layers, ivec2(gl_FragCoord.xy), 0);
}
