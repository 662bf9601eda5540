#version 330
// Hemicube item buffer (Cohen & Greenberg 1985): ONE draw for the five faces of several
// patches.  The vertex buffer holds every vertex once per face slot (in_face); the index
// buffer lists, per face, the triangles the CPU did not cull for it.  Each face's clip square
// is mapped into its own rectangle of the shared framebuffer; gl_ClipDistance keeps every
// triangle inside that rectangle.
//
// A triangle is either a patch's own (in_tag = NO_BLOCK; the fragment shader looks its patch
// up) or half of a block of bilinear-grid cells (in_tag = block * 4 + corner; see
// workbench/renderers/radiosity/hemicube.py, grid_regions): the block's cells and bilinear
// map are fetched here, once per vertex, and passed flat; v_h is the corner's position in
// the block's plane, interpolated to each fragment.
#define MAX_FACES 80
#define TRI_ROW 4096
#define NO_BLOCK 0xFFFFFFFFu
uniform mat4 clip_from_world[MAX_FACES];
uniform vec4 rect[MAX_FACES];   // (scale x, offset x, scale y, offset y) in NDC
uniform float far_plane;
uniform usampler2D block_cells;  // (first patch, nu, nv, stride along a) per block
uniform sampler2D block_map;     // 2 texels per block: (e, f), (g, 0, 0)

in vec3 in_pos;
in uint in_face;
in uint in_tag;
out float v_depth;
out vec2 v_h;
flat out uvec4 v_cells;          // nu = 0: a patch's own triangle
flat out vec4 v_ef;
flat out vec2 v_g;
out float gl_ClipDistance[4];

ivec2 texel(int k) { return ivec2(k % TRI_ROW, k / TRI_ROW); }

void main() {
    vec4 c = clip_from_world[in_face] * vec4(in_pos, 1.0);
    gl_ClipDistance[0] = c.w + c.x;
    gl_ClipDistance[1] = c.w - c.x;
    gl_ClipDistance[2] = c.w + c.y;
    gl_ClipDistance[3] = c.w - c.y;
    vec4 r = rect[in_face];
    gl_Position = vec4(c.x * r.x + c.w * r.y, c.y * r.z + c.w * r.w, c.z, c.w);
    v_depth = c.w / far_plane;   // distance along the face axis, linear (no 1/z precision loss)
    v_cells = uvec4(0u);
    v_ef = vec4(0.0);
    v_g = vec2(0.0);
    v_h = vec2(0.0);
    if (in_tag != NO_BLOCK) {
        int b = int(in_tag / 4u);
        uint corner = in_tag % 4u;
        v_cells = texelFetch(block_cells, texel(b), 0);
        v_ef = texelFetch(block_map, texel(2 * b), 0);
        v_g = texelFetch(block_map, texel(2 * b + 1), 0).xy;
        // corners q0..q3 at (a, b) = (0,0) (1,0) (1,1) (0,1): h = a e + b f + a b g
        v_h = corner == 1u ? v_ef.xy : corner == 2u ? v_ef.xy + v_ef.zw + v_g
            : corner == 3u ? v_ef.zw : vec2(0.0);
    }
}
