#version 330 core
// One fur's shells (workbench/renderers/raster_fur.py): instance k draws shell i = k, or
// N_SHELLS - 1 - k with u_reverse, the base's object-space tessellation scaled per axis by
// (SIZE + o_i) / SIZE, o_i = LENGTH (i + 1/2) / N_SHELLS (fur.shell_scales).
// Needs: N_SHELLS, SIZE, LENGTH.
uniform mat4 u_clip_from_world;
uniform mat4 u_world_from_object;
uniform int u_reverse;

in vec3 in_obj_position;
in vec3 in_obj_normal;

out vec3 v_world;
out vec3 v_obj;
out vec3 v_obj_normal;

void main() {
    int i = u_reverse != 0 ? N_SHELLS - 1 - gl_InstanceID : gl_InstanceID;
    float o = LENGTH * (float(i) + 0.5) / float(N_SHELLS);
    vec3 scale = (SIZE + o) / SIZE;
    v_obj = in_obj_position * scale;
    v_obj_normal = in_obj_normal / scale;  // a normal under diag(scale): scale^-1 n
    v_world = (u_world_from_object * vec4(v_obj, 1.0)).xyz;
    gl_Position = u_clip_from_world * vec4(v_world, 1.0);
}
