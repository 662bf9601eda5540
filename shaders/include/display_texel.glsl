// Which texel of its image a display pass's fragment shows (row 0 of the image on top, as
// display textures store it).  An offscreen pass writes one texel per pixel: the fragment's
// own.  A window pass (TO_WINDOW defined; vertex stage display_window.vert, viewport = the
// image's rectangle in the window) draws the image scaled into that rectangle as a
// nearest-filtered glBlitFramebuffer would: the texel under the fragment's centre,
// floor(v_texel), v_texel interpolated from the texel window's edges at the corners.
#ifdef TO_WINDOW
in vec2 v_texel;

ivec2 image_texel(ivec2 size) {
    return clamp(ivec2(floor(v_texel)), ivec2(0), size - 1);
}
#else
ivec2 image_texel(ivec2 size) {
    return ivec2(gl_FragCoord.xy);
}
#endif
