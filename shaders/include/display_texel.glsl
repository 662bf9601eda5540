// Which texel of its image a display pass's fragment shows (row 0 of the image on top, as
// display textures store it).  An offscreen pass writes one texel per pixel: the fragment's
// own.  A window pass (TO_WINDOW defined) draws the image scaled into its rectangle of the
// window as a nearest-filtered glBlitFramebuffer would: along each axis
// texel = floor(s0 + (p - d0) k), p the fragment's centre, s0 the texel edge drawn at window
// coordinate d0 and k texels per window pixel (negative along y: the window's rows go up,
// the image's down).
#ifdef TO_WINDOW
uniform vec4 u_window;  // (s0.x, s0.y, d0.x, d0.y)
uniform vec2 u_texels_per_pixel;

ivec2 image_texel(ivec2 size) {
    vec2 t = floor(u_window.xy + (gl_FragCoord.xy - u_window.zw) * u_texels_per_pixel);
    return clamp(ivec2(t), ivec2(0), size - 1);
}
#else
ivec2 image_texel(ivec2 size) {
    return ivec2(gl_FragCoord.xy);
}
#endif
