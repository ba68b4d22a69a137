// encode.glsl -- 8-bit output pass: box filter, exposure, the exact sRGB curve (DESIGN section 2).
//
//   c = exposure * mean of the SUPERSAMPLE x SUPERSAMPLE linear radiance texels of this pixel;
//   srgb_encode(c) = 12.92 c for c <= 0.0031308, else 1.055 c^(1/2.4) - 0.055, after clamping c
//   to [0, 1] (NaN to 0); the UNORM8 target rounds it to 8 bits.  Shading stays linear: this is
//   a separate pass after it.  Numpy twin: glphong.imaging.srgb_encode.
// Key defines read here: SUPERSAMPLE.

uniform sampler2D u_radiance;   // linear radiance [W/(m^2 sr)], SUPERSAMPLE times the output size
uniform float u_exposure;       // > 0
layout(location = 0) out vec4 out_color;

vec3 srgb_encode(vec3 linear)
{
    vec3 x = clamp(linear, 0.0, 1.0);
    x = mix(x, vec3(0.0), isnan(linear));
    vec3 low = 12.92 * x;
    vec3 high = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(high, low, lessThanEqual(x, vec3(0.0031308)));
}

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
