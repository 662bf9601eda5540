#version 330 core
// The environment seen through each pixel (what rays leaving the scene see).
in vec2 v_ndc;
const bool HAS_UV_ATTR = false;
const vec2 v_uv = vec2(0.0);
#include "texturing.glsl"

uniform mat4 u_world_from_clip;
out vec4 frag_color;

void main() {
    vec4 a = u_world_from_clip * vec4(v_ndc, -1.0, 1.0);
    vec4 b = u_world_from_clip * vec4(v_ndc, 1.0, 1.0);
    frag_color = vec4(environment(b.xyz / b.w - a.xyz / a.w), 1.0);
}
