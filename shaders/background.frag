#version 330 core
// The environment seen through each pixel (what rays leaving the scene see).
in vec3 v_dir;
const bool HAS_UV_ATTR = false;
const vec2 v_uv = vec2(0.0);
#include "texturing.glsl"

out vec4 frag_color;

void main() {
    frag_color = vec4(environment(v_dir), 1.0);
}
