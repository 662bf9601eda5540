#version 330 core
// A user's shading model compiled alone (workbench/renderers/user_shading.py), only when it
// failed inside raster.frag: the user's text is appended as source string 0 after this fixed
// prelude, so that every message about source 0 is about the user's file.  (Mesa reports some
// errors, e.g. an undeclared name, with source-string number 0 whatever the #line said.)
// What a shading model may use: the Material struct, TOL_ZERO, safe_normalize(), its own
// parameters and GLSL's built-ins.
#include "common.glsl"
#include "user_material.glsl"

vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m);

out vec4 frag_color;

void main() {
    vec3 up = vec3(0.0, 0.0, 1.0);
    frag_color = vec4(shade(vec3(0.0), up, up, up, Material(vec3(1.0), vec3(0.0), 0.0, 1.0, 0.0, 1.0, 0.0)), 1.0);
}
