#version 330 core
// The UI's display modes on the GPU (workbench.core.display): a linear float image -> the
// 8-bit sRGB levels of the mode, one texel per pixel.  The 24-bit frame buffer first
// (e = floor(255 encode(x) + 0.5) / 255, as display_srgb.frag), then either
//  * a direct mode (u_indexed = 0): each channel rounded to u_levels = 2^bits - 1 levels,
//    with u_bayer = 1 the 8 x 8 Bayer (1973) threshold t added first, e + (t - 0.5) / levels
//    (core.display._show), or
//  * an indexed mode (u_indexed = 1): the CLUT entry nearest to e read from u_lut, a 3D table
//    of the nearest entry per cell of 2^u_shift 8-bit levels per channel (built on the CPU
//    from the CLUT: workbench.app.ui.display_modes.clut_table).
// Output row 0 is the image's top row; u_flip = 1 when the source has row 0 at the bottom.
// Into a display texture, or straight into the window (display_texel.glsl).
#include "display_texel.glsl"
uniform sampler2D u_linear;
uniform sampler3D u_lut;
uniform int u_flip;
uniform int u_indexed;
uniform int u_shift;
uniform int u_bayer;
uniform vec3 u_levels;
out vec4 f_color;

vec3 srgb_encode(vec3 x) {
    x = clamp(mix(x, vec3(0.0), isnan(x)), 0.0, 1.0);
    vec3 lo = 12.92 * x;
    vec3 hi = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(x, vec3(0.0031308)));
}

int quadrant(int i, int j) {  // Bayer's 2 x 2 offsets [[0, 2], [3, 1]] (row i, column j)
    return (i & 1) == 0 ? 2 * (j & 1) : 3 - 2 * (j & 1);
}

float bayer8(ivec2 rc) {  // M_8(i, j) = 16 M_2(i, j) + 4 M_2(i/2, j/2) + M_2(i/4, j/4)
    int i = rc.x, j = rc.y;
    int m = 16 * quadrant(i, j) + 4 * quadrant(i >> 1, j >> 1) + quadrant(i >> 2, j >> 2);
    return (float(m) + 0.5) / 64.0;
}

void main() {
    ivec2 size = textureSize(u_linear, 0);
    ivec2 ij = image_texel(size);  // column, output row (row 0 on top)
    ivec2 src = ij;
    if (u_flip == 1) src.y = size.y - 1 - src.y;
    vec3 e = floor(srgb_encode(texelFetch(u_linear, src, 0).rgb) * 255.0 + 0.5) / 255.0;
    vec3 shown;
    if (u_indexed == 1) {
        ivec3 level = ivec3(e * 255.0 + 0.5);
        shown = texelFetch(u_lut, level >> u_shift, 0).rgb;
    } else {
        if (u_bayer == 1) {
            float t = bayer8(ivec2(ij.y & 7, ij.x & 7));
            e = clamp(e + (t - 0.5) / u_levels, 0.0, 1.0);
        }
        shown = floor(e * u_levels + 0.5) / u_levels;
    }
    f_color = vec4(floor(shown * 255.0 + 0.5) / 255.0, 1.0);
}
