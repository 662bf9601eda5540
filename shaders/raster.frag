#version 330 core
// Fragment stage of flat, Gouraud and Phong shading: texture colour C per fragment, then
// I = E + C * diffuse + specular (local model, lighting.glsl; or a user's model, USER_MODEL:
// user_model.glsl), + kr * environment(reflected)
// for environment-mapped materials; opacity maps cut out (alpha < 0.5) or blend.
// Output: linear RGB and alpha into a float32 colour attachment.
#include "varyings.glsl"
#ifdef NEEDS_SURFACE
in vec3 v_world;
#ifdef MODE_FLAT
flat in vec3 v_normal;
#else
in vec3 v_normal;
#endif
#endif
#ifdef NEEDS_OBJ
in vec3 v_obj;
#endif
#ifdef HAS_UV
in vec2 v_uv;
const bool HAS_UV_ATTR = true;
#else
const vec2 v_uv = vec2(0.0);
const bool HAS_UV_ATTR = false;
#endif

#include "standins.glsl"
#include "lighting.glsl"
#include "texturing.glsl"
#ifdef USER_MODEL
#include "user_model.glsl"
#endif
#if defined(MODE_FLAT)
flat in vec3 v_diffuse;
flat in vec3 v_specular;
#elif defined(MODE_GOURAUD)
in vec3 v_diffuse;
in vec3 v_specular;
#endif
#include "screen_space.glsl"
#if defined(MODE_GOURAUD) && defined(SHADOW_MAPS)
in vec3 v_light_d[N_LIGHTS];
in vec3 v_light_s[N_LIGHTS];
#endif
#if defined(MODE_GOURAUD) && defined(ENV_CUBE)
in vec3 v_env;
#endif

uniform vec3 u_eye;
// the material's C, E and kr: literals MAT_COLOR, MAT_EMISSION, MAT_KR (material_defines)
#ifdef DEPTH_LEVELS
uniform float u_depth_levels;  // 2^bits - 1: emulated fixed-point depth buffer
#endif

out vec4 frag_color;

void main() {
    float a = 1.0;
#ifdef OPACITY_KIND
    a = opacity(v_obj, v_uv);
    if (a < 0.5) discard;
#endif
    vec3 C = MAT_COLOR;
#ifdef TEX_KIND
    C *= texture_color(v_obj, v_uv);
#endif
#ifdef NEEDS_SURFACE
    vec3 S = safe_normalize(u_eye - v_world);
    // shading normal: interpolated (or the polygon's, flat); a cancelled one falls back to
    // the triangle's geometric normal
    vec3 Ng = cross(dFdx(v_world), dFdy(v_world));  // outside any branch (derivatives)
    vec3 N = safe_normalize(length(v_normal) < TOL_NORMAL_CANCEL ? Ng : v_normal);
#ifdef BUMP_KIND
    N = bump_normal(v_obj, N);
#endif
    bool inside = dot(v_normal, S) < 0.0;  // the viewer on the inner side (outward normals)
    N = face_viewer(N, S);
#endif
#if defined(USER_MODEL)
    // a user's shading model (user_model.glsl) in place of the local model
    vec3 color = MAT_EMISSION + C * (MAT_KA * SCENE_AMBIENT) + user_terms(v_world, N, S, C);
#else
#ifdef MODE_PHONG
    vec3 diffuse, specular;
    local_terms(v_world, N, S, diffuse, specular);
#else
    vec3 diffuse = v_diffuse;
    vec3 specular = v_specular;
#if defined(MODE_GOURAUD) && defined(SHADOW_MAPS)
    // unrolled over the lights (FOR_EACH_LIGHT, as light_terms in the vertex stage), so that
    // every index is a constant: llvmpipe pays for a loop's dynamically indexed arrays
    int k = 0;
#define X(POINT, INV_SQ, LOBE, pos, color, lobe_normal) \
    { float vis = shadow_visibility(k, v_world, N); \
      diffuse += vis * v_light_d[k]; specular += vis * v_light_s[k]; ++k; }
    FOR_EACH_LIGHT(X)
#undef X
#endif
#endif
    vec3 color = MAT_EMISSION + C * diffuse + specular;
#endif
#if defined(ENV_CUBE) && defined(MODE_GOURAUD)
    color += v_env;  // stand-in environment map, per vertex
#elif defined(ENV_CUBE)
    color += env_terms(v_world, N, S, C, inside);  // stand-in environment map (standins.glsl)
#elif defined(ENV_MAP) && defined(ENV_KIND)
    color += MAT_KR * environment(2.0 * dot(N, S) * N - S);
#endif
    frag_color = vec4(color, a);
#ifdef TINT_PASS
    // stand-in transparency, first of two passes: the colour behind is multiplied by kt C
    // (blend ZERO, SRC_COLOR); the second pass adds this surface's own light (ONE, ONE)
    frag_color = vec4(MAT_KT * C, 1.0);
#endif
#ifdef DEPTH_LEVELS
    gl_FragDepth = floor(gl_FragCoord.z * u_depth_levels + 0.5) / u_depth_levels;
#endif
}
