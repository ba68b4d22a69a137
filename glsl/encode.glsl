// encode.glsl -- 8-bit output pass: box filter, exposure, the exact sRGB curve (docs/design.md section 2).
//
//   c = exposure * mean of the SUPERSAMPLE x SUPERSAMPLE linear radiance texels of this pixel;
//   out = srgb_encode(c) (srgb.glsl); the UNORM8 target rounds it to 8 bits.  Shading stays
//   linear: this is a separate pass after it.
// Key defines read here: SUPERSAMPLE.

uniform sampler2D u_radiance;   // linear radiance [W/(m^2 sr)], SUPERSAMPLE times the output size
uniform float u_exposure;       // > 0
layout(location = 0) out vec4 out_color;

void main()
{
    ivec2 base = ivec2(gl_FragCoord.xy) * SUPERSAMPLE;
    vec3 sum = vec3(0.0);
    for (int j = 0; j < SUPERSAMPLE; ++j) {
        for (int i = 0; i < SUPERSAMPLE; ++i) {
            sum += texelFetch(u_radiance, base + ivec2(i, j), 0).rgb;
        }
    }
    out_color = vec4(srgb_encode(u_exposure * sum / float(SUPERSAMPLE * SUPERSAMPLE)), 1.0);
}
