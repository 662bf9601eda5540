#version 330 core
// Vertex stage of flat, Gouraud and Phong shading (MODE_FLAT | MODE_GOURAUD | MODE_PHONG).
// Positions and normals arrive in world space (the tessellator transforms them); the object-
// space point travels along for the textures.  Flat: one lighting per polygon, at its centroid
// with its normal (flat varyings: the provoking vertex of each triangle carries the polygon's
// normal and centroid, tessellate_topology.provoking_layout).  Gouraud: lighting at the vertex
// with the averaged normal.
#include "standins.glsl"
#include "lighting.glsl"
#include "varyings.glsl"

in vec3 in_position;
in vec3 in_normal;
in vec3 in_obj_position;
#ifdef HAS_UV
in vec2 in_uv;
#endif
#ifdef MODE_FLAT
in vec3 in_centroid;
#endif

uniform mat4 u_clip_from_world;
#ifdef SCREEN_SPACE
out float v_screen_w;  // screen_space.glsl
#endif
uniform vec3 u_eye;

#ifdef NEEDS_SURFACE
out vec3 v_world;
#ifdef MODE_FLAT
flat out vec3 v_normal;  // the polygon's (provoking vertex)
#else
out vec3 v_normal;
#endif
#endif
#ifdef NEEDS_OBJ
out vec3 v_obj;
#endif
#ifdef HAS_UV
out vec2 v_uv;
#endif
#if defined(MODE_FLAT)
flat out vec3 v_diffuse;
flat out vec3 v_specular;
#elif defined(MODE_GOURAUD)
out vec3 v_diffuse;
out vec3 v_specular;
#endif
#if defined(MODE_GOURAUD) && defined(SHADOW_MAPS)
// stand-in shadows: each light's terms apart, weighed per fragment (lighting.glsl light_terms)
out vec3 v_light_d[N_LIGHTS];
out vec3 v_light_s[N_LIGHTS];
#endif
#if defined(MODE_GOURAUD) && defined(ENV_CUBE)
out vec3 v_env;  // stand-in environment map looked up per vertex (standins.glsl env_terms)
#endif

void main() {
#ifdef NEEDS_SURFACE
    v_world = in_position;
    v_normal = in_normal;
#endif
#ifdef NEEDS_OBJ
    v_obj = in_obj_position;
#endif
#ifdef HAS_UV
    v_uv = in_uv;
#endif
#if defined(MODE_FLAT) || defined(MODE_GOURAUD)
#ifdef MODE_FLAT
    vec3 P = in_centroid;
#else
    vec3 P = in_position;
#endif
    vec3 S = safe_normalize(u_eye - P);
    vec3 N = face_viewer(safe_normalize(in_normal), S);
    bool inside = dot(in_normal, S) < 0.0;  // the viewer on the inner side (outward normals)
    local_terms(P, N, S, v_diffuse, v_specular);
#if defined(MODE_GOURAUD) && defined(SHADOW_MAPS)
    v_diffuse = MAT_KA * SCENE_AMBIENT;
    v_specular = vec3(0.0);
    light_terms(P, N, S, v_light_d, v_light_s);
#endif
#if defined(MODE_GOURAUD) && defined(ENV_CUBE)
    v_env = env_terms(P, N, S, MAT_COLOR, inside);
#endif
#endif
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
#ifdef SCREEN_SPACE
    // screen_space.glsl: every smooth varying travels as a * w, beside w
    float w = gl_Position.w;
    v_screen_w = w;
#ifdef NEEDS_SURFACE
    v_world *= w;
#ifndef MODE_FLAT
    v_normal *= w;
#endif
#endif
#ifdef NEEDS_OBJ
    v_obj *= w;
#endif
#ifdef HAS_UV
    v_uv *= w;
#endif
#ifdef MODE_GOURAUD
    v_diffuse *= w;
    v_specular *= w;
#endif
#endif
}
