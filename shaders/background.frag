#version 330 core
// The environment seen through each pixel (what rays leaving the scene see).
#include "texturing.glsl"

in vec2 v_ndc;
uniform mat4 u_world_from_clip;
out vec4 frag_color;

void main() {
    vec4 a = u_world_from_clip * vec4(v_ndc, -1.0, 1.0);
    vec4 b = u_world_from_clip * vec4(v_ndc, 1.0, 1.0);
    frag_color = vec4(environment(b.xyz / b.w - a.xyz / a.w), 1.0);
}
