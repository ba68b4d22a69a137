// transmission_pyramid.glsl -- one level of the transmission background's pyramid of 2x2 box means, drawn from the
// level above it (glphong/gpu/transmission.py, docs/transmission.md), over the texels (i, j) of level k + 1:
//
//   B_{k+1}(i, j) = ((B_k(x0, y0) + B_k(x1, y0)) + (B_k(x0, y1) + B_k(x1, y1))) * 0.25   (float32 RGBA)
//   x0 = min(2 i, w_k - 1), x1 = min(2 i + 1, w_k - 1), y0 = min(2 j, h_k - 1), y1 = min(2 j + 1, h_k - 1)
//
// w_k, h_k the size of level k (GL's: level k + 1 is max(floor(w_k / 2), 1) by max(floor(h_k / 2), 1)); the clamp
// repeats the last column or row where level k is 1 wide or high.  In this order of operations, each sum and the
// scaling by 0.25 rounded once to nearest, it is the host's glphong.materials.gltf_transmission.background_levels in
// float32 (numpy, IEEE 754 with subnormals), bit for bit (tests/test_transmission_pass.py, EGL and OSMesa).
// Subnormals: llvmpipe (and most GPUs' fragment stages) flush them to zero, so a channel whose four texels are all
// below 2^60 in magnitude is summed scaled by 2^64 instead (pyramid_scaled: exact, a subnormal texel read from its
// bits), where no subnormal arises, and scaled back with IEEE's rounding to nearest even onto the subnormal grid
// where the mean is below 2^-126 (pyramid_unscaled, on the bits); the other channels (a texel at least 2^60, Inf,
// NaN) as written.  numpy needs neither (its arithmetic keeps subnormals): they are exact rescalings, not formulas.
// Key defines read here: none.

uniform sampler2D u_background;  // the background texture; its levels 0 to k are written
uniform int u_level;             // k
layout(location = 0) out vec4 out_color;

// x 2^64, exactly, a subnormal x (bits of exponent 0, which arithmetic may take for 0) from its integer mantissa
vec4 pyramid_scaled(vec4 x)
{
    uvec4 bits = floatBitsToUint(x);
    vec4 tiny = vec4(bits & 0x7FFFFFu) * uintBitsToFloat(42u << 23);  // mantissa 2^-149 2^64 = mantissa 2^-85
    tiny = mix(tiny, -tiny, notEqual(bits & 0x80000000u, uvec4(0u)));
    return mix(x * uintBitsToFloat(191u << 23), tiny, equal(bits & 0x7F800000u, uvec4(0u)));
}

// q 2^-64 rounded to float32 to nearest even, subnormal results included (built from the bits where the biased
// exponent e of q is at most 64: the mantissa m 2^(e - 65) in units of 2^-149; q 2^-64 exactly above)
vec4 pyramid_unscaled(vec4 q)
{
    uvec4 bits = floatBitsToUint(q);
    uvec4 e = (bits >> 23) & 0xFFu;
    uvec4 m = (bits & 0x7FFFFFu) | 0x800000u;
    uvec4 shift = min(uvec4(65u) - min(e, uvec4(64u)), uvec4(31u));
    uvec4 n = m >> shift;
    uvec4 rest = m & ((uvec4(1u) << shift) - 1u);
    uvec4 half_unit = uvec4(1u) << (shift - 1u);
    n += uvec4(greaterThan(rest, half_unit)) | (uvec4(equal(rest, half_unit)) & (n & 1u));
    vec4 subnormal = uintBitsToFloat((bits & 0x80000000u) | n);
    return mix(q * uintBitsToFloat(63u << 23), subnormal, lessThanEqual(e, uvec4(64u)));
}

void main()
{
    ivec2 last = textureSize(u_background, u_level) - 1;
    ivec2 p0 = min(2 * ivec2(gl_FragCoord.xy), last);
    ivec2 p1 = min(2 * ivec2(gl_FragCoord.xy) + 1, last);
    vec4 a = texelFetch(u_background, p0, u_level);
    vec4 b = texelFetch(u_background, ivec2(p1.x, p0.y), u_level);
    vec4 c = texelFetch(u_background, ivec2(p0.x, p1.y), u_level);
    vec4 d = texelFetch(u_background, p1, u_level);
    vec4 plain = ((a + b) + (c + d)) * 0.25;
    vec4 scaled = ((pyramid_scaled(a) + pyramid_scaled(b)) + (pyramid_scaled(c) + pyramid_scaled(d))) * 0.25;
    vec4 largest = max(max(abs(a), abs(b)), max(abs(c), abs(d)));
    out_color = mix(plain, pyramid_unscaled(scaled), lessThan(largest, vec4(uintBitsToFloat(187u << 23))));
}
