#version 330 core
// The UI's display pass: a linear float image -> 8-bit sRGB, one texel per pixel (no
// filtering), into a display texture or straight into the window (display_texel.glsl).
// Same numbers as workbench.core.imageio.to_srgb8: NaN -> 0, clip to [0, 1],
// IEC 61966-2-1 transfer function, then floor(255 c + 0.5) so that the RGBA8 target stores
// exactly the level to_srgb8 gives (up to float32 rounding of pow).
// Output row 0 is the image's top row; u_flip = 1 when the source has row 0 at the bottom
// (an OpenGL framebuffer), 0 when it was uploaded from a top-row-first array.
#include "display_texel.glsl"
uniform sampler2D u_linear;
uniform int u_flip;
out vec4 f_color;

vec3 srgb_encode(vec3 x) {
    x = clamp(mix(x, vec3(0.0), isnan(x)), 0.0, 1.0);
    vec3 lo = 12.92 * x;
    vec3 hi = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(x, vec3(0.0031308)));
}

void main() {
    ivec2 size = textureSize(u_linear, 0);
    ivec2 ij = image_texel(size);
    if (u_flip == 1) ij.y = size.y - 1 - ij.y;
    vec3 c = srgb_encode(texelFetch(u_linear, ij, 0).rgb);
    f_color = vec4(floor(c * 255.0 + 0.5) / 255.0, 1.0);
}
