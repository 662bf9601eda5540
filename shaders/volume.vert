#version 330 core
// Full-screen triangle for a hypertexture's ray march (volume.frag computes each pixel's ray
// from gl_FragCoord; the caller's scissor box keeps the fragments near the medium).
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
