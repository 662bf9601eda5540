#version 330
// Radiosity display (Cohen & Greenberg 1985): the solution interpolated to vertices, drawn
// with Gouraud shading from the scene camera.
uniform mat4 clip_from_world;
in vec3 in_pos;
in vec3 in_radiance;
out vec3 v_radiance;

void main() {
    gl_Position = clip_from_world * vec4(in_pos, 1.0);
    v_radiance = in_radiance;
}
