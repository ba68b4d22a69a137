// matte_fragment.glsl -- the matte pass: which object each sub-pixel sample sees (docs/design.md section 15).
//
// out_object = u_object_id + 1 (the object's index in the scene plus one; 0 is the background, the target's clear
// value).  The pass draws every object with the depth test (GL_LESS) into an unsigned-integer target at `samples`
// times the output size along each axis (a regular grid of samples at the centres of a pixel's s x s cells); the
// host counts each pixel's samples per object: fraction = count / s^2 (glphong.gpu.matte).  The index is exact as a
// float below 2^24.
// Key defines read here: none.

uniform float u_object_id;
layout(location = 0) out uint out_object;

void main()
{
    out_object = uint(u_object_id) + 1u;
}
