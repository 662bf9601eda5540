#version 330 core
// The UI's colour scale: a value image (row 0 on top) in [0, vmax] -> the colour of a
// (n x 1) display-space table, entry floor(clip(v / vmax, 0, 1) (n - 1)) as
// workbench.app.ui.panels.colour_scale does, into a display texture or straight into the
// window (display_texel.glsl).  vmax is the image's maximum as the GPU reduced it
// (display_stats.frag: texel (0, 0) of u_stats, r), at least u_floor.
#include "display_texel.glsl"
uniform sampler2D u_value;
uniform sampler2D u_table;
uniform sampler2D u_stats;
uniform float u_floor;
out vec4 f_color;

void main() {
    float scale = 1.0 / max(texelFetch(u_stats, ivec2(0, 0), 0).r, u_floor);
    ivec2 ij = image_texel(textureSize(u_value, 0));
    float v = clamp(texelFetch(u_value, ij, 0).r * scale, 0.0, 1.0);
    int n = textureSize(u_table, 0).x;
    f_color = vec4(texelFetch(u_table, ivec2(int(v * float(n - 1)), 0), 0).rgb, 1.0);
}
