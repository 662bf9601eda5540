#version 330 core
// The UI's window passes (display_*.frag with TO_WINDOW): a quad covering the viewport,
// which is the image's rectangle in the window, and at each corner the texel coordinates it
// shows (display_texel.glsl).  u_src = (left, bottom, right, top) edges of the image's texel
// window, rows counted from the image's top row (so bottom > top).  The four corners come
// from gl_VertexID (a triangle strip, no vertex buffer).
uniform vec4 u_src;
out vec2 v_texel;

void main() {
    vec2 c = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
    v_texel = mix(u_src.xy, u_src.zw, c);
    gl_Position = vec4(2.0 * c - 1.0, 0.0, 1.0);
}
