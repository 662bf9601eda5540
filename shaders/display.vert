#version 330 core
// Full-screen triangle for the UI's display passes (display_*.frag): no vertex buffer, the
// three corners come from gl_VertexID.
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
