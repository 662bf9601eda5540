#version 330
// A patch's back face received nothing (patches are one-sided): it shows black.
in vec3 v_radiance;
out vec4 color;

void main() {
    color = vec4(gl_FrontFacing ? v_radiance : vec3(0.0), 1.0);
}
