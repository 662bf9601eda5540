#version 330 core
// Depth-only pass of the stand-in shadow maps (Williams 1978; raster_standins.py): the scene
// seen from a light, one tile of the shadow atlas per pass.
in vec3 in_position;
uniform mat4 u_clip_from_world;

void main() {
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
}
