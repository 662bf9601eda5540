#version 330 core
// The UI's window pass for an image already in display space (a display texture: RGBA8 or
// RGB8, row 0 on top): copied into its rectangle of the window, scaled as a nearest blit
// (display_texel.glsl, TO_WINDOW).
#include "display_texel.glsl"
uniform sampler2D u_image;
out vec4 f_color;

void main() {
    f_color = vec4(texelFetch(u_image, image_texel(textureSize(u_image, 0)), 0).rgb, 1.0);
}
