// SCREEN_SPACE (raster_shaders.material_defines): the course's scanline interpolation, linear
// in screen space along edges and spans, for every smooth varying.  GLSL's noperspective says
// the same, but llvmpipe's clipper gives such varyings NaN at the corners the near plane adds;
// so each varying a travels perspective-correct as a * w (raster.vert multiplies it by the
// clip w), beside w itself (v_screen_w): with screen barycentrics l_i, perspective-correct
// interpolation gives (sum l_i a_i w_i / w_i) / (sum l_i / w_i) and (sum l_i) / (sum l_i / w_i),
// whose ratio is sum l_i a_i, the screen-linear value; at a clipped corner, t along an edge in
// clip space, it is a_0 + s (a_1 - a_0) with s = t w_1 / ((1 - t) w_0 + t w_1), the point the
// corner projects to.  Included by raster.frag after its inputs: from here on each name reads
// the ratio (a macro is not expanded inside its own expansion).
#ifdef SCREEN_SPACE
in float v_screen_w;
#ifdef NEEDS_SURFACE
#define v_world (v_world / v_screen_w)
#ifndef MODE_FLAT
#define v_normal (v_normal / v_screen_w)
#endif
#endif
#ifdef NEEDS_OBJ
#define v_obj (v_obj / v_screen_w)
#endif
#ifdef HAS_UV
#define v_uv (v_uv / v_screen_w)
#endif
#ifdef MODE_GOURAUD
#define v_diffuse (v_diffuse / v_screen_w)
#define v_specular (v_specular / v_screen_w)
#endif
#endif
