// my_shader.glsl: two helpers of a user's shader, tested by examples/test_my_shader.py.

// Reinhard's tone curve with a white point [W/(m^2 sr)]: L (1 + L / white^2) / (1 + L), per channel.
// A radiance of `white` maps to 1; the curve is increasing and maps [0, white] into [0, 1].
vec3 tone_reinhard(vec3 radiance, float white)
{
    return radiance * (vec3(1.0) + radiance / (white * white)) / (vec3(1.0) + radiance);
}

// Wrapped diffuse lighting: max((n.l + w) / (1 + w), 0) for unit n and l and a wrap w in [0, 1].
float wrap_diffuse(vec3 n, vec3 l, float w)
{
    return max((dot(n, l) + w) / (1.0 + w), 0.0);
}
