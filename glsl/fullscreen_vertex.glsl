// fullscreen_vertex.glsl -- one triangle covering the viewport, for image post-passes.
//
//   vertex k in {0, 1, 2} -> clip position (-1 + 4 (k == 1), -1 + 4 (k == 2)); no attributes.

void main()
{
    vec2 corner = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(corner, 0.0, 1.0);
}
