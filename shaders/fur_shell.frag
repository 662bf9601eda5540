#version 330 core
// One shell fragment of a fur (the model of workbench/renderers/raster_fur.py, twin of
// zbuffer_fur.py): the texel D at the fragment's object-space point; where D = 1 the layer's
// opacity a = 1 - exp(-DENSITY min(LAYER / |cos|, LENGTH)) (LAYER = LENGTH / N_SHELLS, cos
// between the view ray and the shell's normal, object space: radial on a
// sphere, the face's on a box) and the Kajiya-Kay source
// J = ALBEDO Ia + sum_l I_l (ALBEDO sin(T, L) + spec) with no shadowing; output (a J, a),
// blended (ONE, ONE_MINUS_SRC_ALPHA) back to front.
// Needs: fur_texel.glsl's, LAYER, DENSITY, ALBEDO, SCENE_AMBIENT, FOR_EACH_LIGHT, TOL_ZERO.
#include "common.glsl"
#include "fur_texel.glsl"

uniform vec3 u_eye;
uniform mat3 u_object_from_world;  // linear part
uniform mat3 u_normal_matrix;      // world normal from object normal

in vec3 v_world;
in vec3 v_obj;
in vec3 v_obj_normal;

out vec4 frag_color;

#ifndef FOR_EACH_LIGHT
#define FOR_EACH_LIGHT(X)
#endif

// One light's Kajiya-Kay terms (the lights of lighting.glsl's add_light: position or direction
// towards it, colour * intensity, 1 / r^2 and emitter-lobe factors).
void fur_light(bool POINT, bool INV_SQ, bool LOBE, vec3 pos, vec3 color, vec3 lobe_normal,
               vec3 P, vec3 T, vec3 d, inout vec3 J) {
    vec3 v = POINT ? pos - P : pos;
    float r2 = dot(v, v);
    if (!(r2 > TOL_ZERO * TOL_ZERO)) return;
    vec3 L = v * inversesqrt(r2);
    float scale = 1.0;
    if (INV_SQ) scale = 1.0 / r2;
    if (LOBE) scale *= max(0.0, -dot(L, lobe_normal));
    vec2 kk = kajiya_kay(T, L, d);
    J += color * scale * (ALBEDO * kk.x + kk.y);
}

void main() {
    vec3 T_obj;
    if (fur_texel(v_obj, T_obj) == 0.0) discard;
    vec3 d = safe_normalize(v_world - u_eye);
#if BASE_BOX
    vec3 n = v_obj_normal;  // the face's
#else
    vec3 n = v_obj;         // radial
#endif
    float c = abs(dot(safe_normalize(u_object_from_world * d), safe_normalize(n)));
    float a = 1.0 - exp(-DENSITY * min(LAYER / max(c, 1.0e-30), LENGTH));
    vec3 T = safe_normalize(u_normal_matrix * T_obj);
    vec3 J = ALBEDO * SCENE_AMBIENT;
#define X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) \
    fur_light(POINT, INV_SQ, LOBE, pos, color, lobe_normal, v_world, T, d, J);
    FOR_EACH_LIGHT(X)
#undef X
    frag_color = vec4(a * J, a);
}
