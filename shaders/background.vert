#version 330 core
// Full-screen triangle at the far plane (depth 1) for the environment background, drawn after
// the opaque surfaces with depth test "<=": only pixels nothing covers are shaded.  The view
// direction (camera frame: x * tan_x, y * tan_y, -1) is linear in screen position, so it is
// computed here and interpolated exactly.
uniform mat3 u_world_from_camera;  // rotation part
uniform vec2 u_tan;                // tan(fov_x / 2), tan(fov_y / 2)
out vec3 v_dir;

void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    v_dir = u_world_from_camera * vec3(p * u_tan, -1.0);
    gl_Position = vec4(p, 1.0, 1.0);
}
