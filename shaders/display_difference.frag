#version 330 core
// The UI's difference view, kind "abs": per pixel, the mean over RGB of |a - b| on linear
// values clipped to [0, 1] (workbench.compare.metrics.error_map), one texel per pixel, row 0
// of the output on top.  u_flip_* = 1 when that input has row 0 at the bottom (a framebuffer).
uniform sampler2D u_a;
uniform sampler2D u_b;
uniform int u_flip_a;
uniform int u_flip_b;
out float f_error;

vec3 fetch(sampler2D s, int flip) {
    ivec2 ij = ivec2(gl_FragCoord.xy);
    if (flip == 1) ij.y = textureSize(s, 0).y - 1 - ij.y;
    return clamp(texelFetch(s, ij, 0).rgb, 0.0, 1.0);
}

void main() {
    vec3 d = abs(fetch(u_a, u_flip_a) - fetch(u_b, u_flip_b));
    f_error = (d.r + d.g + d.b) / 3.0;
}
