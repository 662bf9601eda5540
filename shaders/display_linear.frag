#version 330 core
// The UI's window pass for a linear float image (row 0 at the bottom when u_flip = 1) into a
// window whose framebuffer encodes sRGB itself (GL_FRAMEBUFFER_SRGB enabled on an sRGB-capable
// window): the linear value is written and the framebuffer stores its 8-bit sRGB level.  The
// rasteriser's encoding may round a level the other way from display_srgb.frag's exact
// transfer function (llvmpipe: at most one level); it serves while an image changes every
// frame (a drag), display_srgb.frag's exact levels once it rests.  NaN -> 0.
#include "display_texel.glsl"
uniform sampler2D u_linear;
uniform int u_flip;
out vec4 f_color;

void main() {
    ivec2 size = textureSize(u_linear, 0);
    ivec2 ij = image_texel(size);
    if (u_flip == 1) ij.y = size.y - 1 - ij.y;
    vec3 x = texelFetch(u_linear, ij, 0).rgb;
    f_color = vec4(clamp(mix(x, vec3(0.0), isnan(x)), 0.0, 1.0), 1.0);
}
