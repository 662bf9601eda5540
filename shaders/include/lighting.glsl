// The local lighting model, GLSL mirror of workbench/renderers/local_model.py (tested against it).
//
//   I = E + ka C Ia + sum_l I_l(P) [ kd C max(N.L_l, 0) + ks spec_l ]
//   spec_l = max(R_l.S, 0)^n   (Phong, R_l = 2 (N.L_l) N - L_l)
//          = max(N.H_l, 0)^n   (Blinn, H_l = normalize(L_l + S), with BLINN defined)
//   spec_l = 0 where N.L_l <= 0; x^0 = 1 (GLSL leaves pow(0, 0) undefined: we define it).
//
// It is split as I = E + C * diffuse + specular so that flat and Gouraud shading can light at
// the polygon / vertex and still modulate by a per-fragment texture colour C.
// Needs: N_LIGHTS, TOL_ZERO; SPECULAR when ks > 0 (defines).
#include "common.glsl"

uniform vec3 u_ambient;      // the scene's Ia
uniform float u_ka;
uniform float u_kd;
uniform float u_ks;
uniform float u_shininess;

#if N_LIGHTS > 0
uniform vec4 u_light_pos[N_LIGHTS];     // xyz position (w = 1) or direction towards the light (w = 0)
uniform vec3 u_light_color[N_LIGHTS];   // color * intensity
uniform float u_light_inv_sq[N_LIGHTS]; // 1: inverse-square falloff
uniform vec4 u_light_lobe[N_LIGHTS];    // xyz emitter normal of an area light's stand-in, w = 1 if set
#endif

// x^n with x clamped to [0, 1] and x^0 = 1.
float spec_pow(float x, float n) {
    return n == 0.0 ? 1.0 : pow(clamp(x, 0.0, 1.0), n);
}

// Direction to light l and received intensity at P.  Branch-free (llvmpipe runs both sides
// of a branch it cannot prove uniform): a directional light has w = 0, so d = lp.xyz.
void light_incidence(int l, vec3 P, out vec3 L, out vec3 I) {
#if N_LIGHTS > 0
    vec4 lp = u_light_pos[l];
    vec3 d = lp.xyz - P * lp.w;
    float r2 = dot(d, d);
    L = safe_normalize(d);
    float falloff = mix(1.0, 1.0 / max(r2, TOL_ZERO * TOL_ZERO), u_light_inv_sq[l]);
    float lobe = mix(1.0, max(0.0, -dot(L, u_light_lobe[l].xyz)), u_light_lobe[l].w);
    I = u_light_color[l] * (falloff * lobe);
#else
    L = vec3(0.0);
    I = vec3(0.0);
#endif
}

// N: unit shading normal (already facing the viewer), S: unit vector to the viewer.
// diffuse = ka Ia + sum I_l kd max(N.L, 0) (to multiply by C); specular = sum I_l ks spec_l.
void local_terms(vec3 P, vec3 N, vec3 S, out vec3 diffuse, out vec3 specular) {
    diffuse = u_ka * u_ambient;
    specular = vec3(0.0);
    for (int l = 0; l < N_LIGHTS; ++l) {
        vec3 L, I;
        light_incidence(l, P, L, I);
        float ndl = dot(N, L);
        diffuse += I * (u_kd * max(ndl, 0.0));
#ifdef SPECULAR
#ifdef BLINN
        float base = dot(N, safe_normalize(L + S));
#else
        float base = dot(2.0 * ndl * N - L, S);
#endif
        specular += I * (ndl > 0.0 ? u_ks * spec_pow(base, u_shininess) : 0.0);
#endif
    }
}

// The shading normal turned towards the viewer (two-sided surfaces).
vec3 face_viewer(vec3 N, vec3 S) {
    return dot(N, S) < 0.0 ? -N : N;
}
