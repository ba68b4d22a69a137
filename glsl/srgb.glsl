// srgb.glsl -- the exact piecewise sRGB transfer function (IEC 61966-2-1, docs/design.md section 2).
//
// srgb_encode(linear) -> 12.92 x for x <= 0.0031308, else 1.055 x^(1/2.4) - 0.055,
//   x = clamp(linear, 0, 1), NaN -> 0.  Display values in [0, 1].
// Used only where the output is a display buffer: glphong's 8-bit encode pass, and programs drawn
// into pyrender's 8-bit framebuffer (OUTPUT_DISPLAY), after the linear shading and an exposure.
// Numpy twin: glphong.imaging.srgb_encode.

vec3 srgb_encode(vec3 linear)
{
    vec3 x = clamp(linear, 0.0, 1.0);
    x = mix(x, vec3(0.0), isnan(linear));
    vec3 low = 12.92 * x;
    vec3 high = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(high, low, lessThanEqual(x, vec3(0.0031308)));
}
