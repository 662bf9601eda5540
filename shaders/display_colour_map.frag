#version 330 core
// The UI's colour scale: a value image (row 0 on top) in [0, vmax] -> the colour of a
// (n x 1) display-space table, entry floor(clip(v / vmax, 0, 1) (n - 1)) as
// workbench.app.ui.panels.colour_scale does.
uniform sampler2D u_value;
uniform sampler2D u_table;
uniform float u_scale;  // 1 / vmax
out vec4 f_color;

void main() {
    float v = clamp(texelFetch(u_value, ivec2(gl_FragCoord.xy), 0).r * u_scale, 0.0, 1.0);
    int n = textureSize(u_table, 0).x;
    f_color = vec4(texelFetch(u_table, ivec2(int(v * float(n - 1)), 0), 0).rgb, 1.0);
}
