// A user's shading model in place of the local model (method "glsl:FILE", Phong shading only;
// workbench/renderers/user_shading.py).  The user's file defines
//
//   vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m)
//
// P: world-space point, N: unit shading normal (interpolated, bumped, turned towards the
// viewer), V: unit vector towards the viewer, L: unit vector towards the light, m: the material
// (m.color already multiplied by the texture).  It returns the light reflected towards V per
// unit light colour; the fragment's colour is
//
//   I = E + ka C Ia + sum_l I_l(P) shade(P, N, V, L_l, m)
//
// with I_l(P) the light's colour * intensity times its falloff (1 / r^2 for inverse-square point
// lights) and its lobe (area-light stand-ins): the same light terms as lighting.glsl.  shade() is
// called for every light, facing or not: it clamps N.L itself.  The user's text is appended after
// main() (its prototype is below) behind "#line 1 <n>", so compiler messages name its own lines.
// Needs: FOR_EACH_LIGHT, MAT_* (lighting.glsl), TOL_ZERO.

#include "user_material.glsl"

vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m);

// One light's contribution I_l(P) shade(P, N, V, L, m) (arguments as add_light in lighting.glsl).
vec3 user_light(bool POINT, bool INV_SQ, bool LOBE, vec3 pos, vec3 color, vec3 lobe_normal,
                vec3 P, vec3 N, vec3 V, Material m) {
    vec3 d = POINT ? pos - P : pos;
    float r2 = dot(d, d);
    float inv_r = r2 > TOL_ZERO * TOL_ZERO ? inversesqrt(r2) : 0.0;
    float scale = 1.0;
    if (INV_SQ) scale = 1.0 / max(r2, TOL_ZERO * TOL_ZERO);
    if (LOBE) scale *= max(0.0, -dot(d, lobe_normal) * inv_r);
    return color * scale * shade(P, N, V, d * inv_r, m);
}

// sum_l I_l(P) shade(P, N, V, L_l, m) over the scene's point and directional lights.
vec3 user_terms(vec3 P, vec3 N, vec3 V, vec3 C) {
    Material m = Material(C, MAT_EMISSION, MAT_KA, MAT_KD, MAT_KS, MAT_SHININESS, MAT_KR);
    vec3 sum = vec3(0.0);
#define X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) \
    sum += user_light(POINT, INV_SQ, LOBE, pos, color, lobe_normal, P, N, V, m);
    FOR_EACH_LIGHT(X)
#undef X
    return sum;
}
