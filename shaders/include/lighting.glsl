// The local lighting model, GLSL mirror of workbench/renderers/local_model.py (tested against it).
//
//   I = E + ka C Ia + sum_l I_l(P) [ kd C max(N.L_l, 0) + ks spec_l ]
//   spec_l = max(R_l.S, 0)^n   (Phong, R_l = 2 (N.L_l) N - L_l)
//          = max(N.H_l, 0)^n   (Blinn, H_l = normalize(L_l + S), with BLINN defined)
//   spec_l = 0 where N.L_l <= 0; x^0 = 1 (GLSL leaves pow(0, 0) undefined: we define it).
//
// It is split as I = E + C * diffuse + specular so that flat and Gouraud shading can light at
// the polygon / vertex and still modulate by a per-fragment texture colour C.
// Needs: FOR_EACH_LIGHT, SCENE_AMBIENT, MAT_KA, MAT_KD, MAT_KS, MAT_SHININESS, TOL_ZERO; SPECULAR
// when ks > 0 (defines).
#include "common.glsl"

// The scene's Ia and the material's ka, kd, ks, n are literals (SCENE_AMBIENT, MAT_KA, MAT_KD,
// MAT_KS, MAT_SHININESS from raster_shaders.material_defines), like the lights: llvmpipe reads
// a uniform per fragment, and the compiler folds literals (kd = 1, ka = 0, n = 0, ...).

// Live variants: the MAT_* names above and the lights' values are uniforms (live_values.glsl).
#include "live_values.glsl"

#ifndef FOR_EACH_LIGHT
#define FOR_EACH_LIGHT(X)
#endif
// x^n with x clamped to [0, 1] and x^0 = 1.
float spec_pow(float x, float n) {
    return n == 0.0 ? 1.0 : pow(clamp(x, 0.0, 1.0), n);
}

// One light's terms at P, specialised at compile time (FOR_EACH_LIGHT, built by
// raster_shaders.light_list): the flags POINT (else directional), INV_SQ (1 / r^2 falloff) and
// LOBE (area-light stand-in: max(0, -n_l.L)) and the light's data as literals: position (or
// direction towards a directional light), colour * intensity, emitter normal n_l.  The
// compiler folds them: each light costs only its own arithmetic, and no uniform is read
// (llvmpipe's per-fragment uniform loads cost more than the arithmetic: Cornell Phong, 9
// lights, 23 -> 9 ms CPU per 512 x 512 frame).  With d = (light - P) and L = d / |d|:
// N.L = (N.d) / |d|, and for Phong's R = 2 (N.L) N - L, R.S = 2 (N.L) (N.S) - (d.S) / |d|, so
// L itself is only formed for Blinn's H.  A light at P (d = 0) gives L = 0 as safe_normalize
// would: no light.
void add_light(bool POINT, bool INV_SQ, bool LOBE, vec3 pos, vec3 color, vec3 lobe_normal,
               vec3 P, vec3 N, vec3 S, float NdS, inout vec3 diffuse, inout vec3 specular) {
    vec3 d = POINT ? pos - P : pos;
    float r2 = dot(d, d);
    float inv_r = r2 > TOL_ZERO * TOL_ZERO ? inversesqrt(r2) : 0.0;
    float ndl = dot(N, d) * inv_r;
    float scale = 1.0;
    if (INV_SQ) scale = 1.0 / max(r2, TOL_ZERO * TOL_ZERO);
    if (LOBE) scale *= max(0.0, -dot(d, lobe_normal) * inv_r);
    diffuse += color * (scale * MAT_KD * max(ndl, 0.0));
#ifdef SPECULAR
#ifdef BLINN
    float base = dot(N, safe_normalize(d * inv_r + S));
#else
    float base = 2.0 * ndl * NdS - dot(d, S) * inv_r;
#endif
    specular += color * (ndl > 0.0 ? scale * MAT_KS * spec_pow(base, MAT_SHININESS) : 0.0);
#endif
}

// N: unit shading normal (already facing the viewer), S: unit vector to the viewer.
// diffuse = ka Ia + sum I_l kd max(N.L, 0) (to multiply by C); specular = sum I_l ks spec_l.
// FOR_EACH_LIGHT(X) expands to X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) for each light
// that can contribute (none for a material with kd = ks = 0).
void local_terms(vec3 P, vec3 N, vec3 S, out vec3 diffuse, out vec3 specular) {
    diffuse = MAT_KA * SCENE_AMBIENT;
    specular = vec3(0.0);
    float NdS = dot(N, S);
#if defined(SHADOW_MAPS) && defined(MODE_PHONG)
    // stand-in shadows (standins.glsl): light k's colour times its shadow-map visibility at P
    int k = 0;
#define X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) \
    add_light(POINT, INV_SQ, LOBE, pos, (color) * shadow_visibility(k++, P, N), lobe_normal, P, N, S, NdS, \
              diffuse, specular);
#else
#define X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) \
    add_light(POINT, INV_SQ, LOBE, pos, color, lobe_normal, P, N, S, NdS, diffuse, specular);
#endif
    FOR_EACH_LIGHT(X)
#undef X
}

#if defined(SHADOW_MAPS) && defined(MODE_GOURAUD)
// Gouraud with stand-in shadows: each light's diffuse and specular terms at the vertex apart
// (ld[k], ls[k], without the ambient term), so that the fragment can weigh each by its
// shadow-map visibility after interpolation.
void light_terms(vec3 P, vec3 N, vec3 S, out vec3 ld[N_LIGHTS], out vec3 ls[N_LIGHTS]) {
    for (int i = 0; i < N_LIGHTS; ++i) {
        ld[i] = vec3(0.0);
        ls[i] = vec3(0.0);
    }
    float NdS = dot(N, S);
    int k = 0;
#define X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) \
    add_light(POINT, INV_SQ, LOBE, pos, color, lobe_normal, P, N, S, NdS, ld[k], ls[k]); ++k;
    FOR_EACH_LIGHT(X)
#undef X
}
#endif

// The shading normal turned towards the viewer (two-sided surfaces).
vec3 face_viewer(vec3 N, vec3 S) {
    return dot(N, S) < 0.0 ? -N : N;
}
