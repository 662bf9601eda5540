#version 330
// Hemicube item buffer (Cohen & Greenberg 1985): ONE draw for the five faces of several
// patches.  The vertex buffer holds every scene vertex once per face slot (in_face); the
// index buffer lists, per face, the triangles the CPU did not cull for it.  Each face's clip square is mapped
// into its own rectangle of the shared framebuffer; gl_ClipDistance keeps every triangle
// inside that rectangle.
#define MAX_FACES 80
uniform mat4 clip_from_world[MAX_FACES];
uniform vec4 rect[MAX_FACES];   // (scale x, offset x, scale y, offset y) in NDC
uniform float far_plane;

in vec3 in_pos;
in uint in_face;
out float v_depth;
out float gl_ClipDistance[4];

void main() {
    vec4 c = clip_from_world[in_face] * vec4(in_pos, 1.0);
    gl_ClipDistance[0] = c.w + c.x;
    gl_ClipDistance[1] = c.w - c.x;
    gl_ClipDistance[2] = c.w + c.y;
    gl_ClipDistance[3] = c.w - c.y;
    vec4 r = rect[in_face];
    gl_Position = vec4(c.x * r.x + c.w * r.y, c.y * r.z + c.w * r.w, c.z, c.w);
    v_depth = c.w / far_plane;   // distance along the face axis, linear (no 1/z precision loss)
}
