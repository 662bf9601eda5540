#version 330
// Item buffer: the nearest surface's patch number + 1 where its front face is seen, 0 where
// nothing or a back face is (a back face still hides what is behind it).
//
// A patch's own triangle: gl_PrimitiveID of this draw looks its patch up in tri_patch
// (row-major, TRI_ROW texels per row, written with the index buffer).  A block of nu x nv
// bilinear-grid cells (v_cells.y > 0): the fragment's (a, b) inverts the block's map
//     h = a e + b f + a b g      (2D, in the block's plane)
// b solves (g x f) b^2 + (e x f + h x g) b + h x e = 0 (stable roots, errata 7; the one in
// [0, 1]), a = (h - b f) . s / s . s with s = e + b g; the cell is (floor(a nu), floor(b nv)).
#define TRI_ROW 4096
uniform usampler2D tri_patch;
in float v_depth;
in vec2 v_h;
flat in uvec4 v_cells;
flat in vec4 v_ef;
flat in vec2 v_g;
out uint item;

float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }
float outside(float t) { return max(0.0, max(-t, t - 1.0)); }

void main() {
    gl_FragDepth = v_depth;
    if (!gl_FrontFacing) {
        item = 0u;
        return;
    }
    if (v_cells.y == 0u) {
        ivec2 t = ivec2(gl_PrimitiveID % TRI_ROW, gl_PrimitiveID / TRI_ROW);
        item = texelFetch(tri_patch, t, 0).r + 1u;
        return;
    }
    vec2 e = v_ef.xy, f = v_ef.zw, g = v_g, h = v_h;
    float k2 = cross2(g, f), k1 = cross2(e, f) + cross2(h, g), k0 = cross2(h, e);
    float disc = sqrt(max(k1 * k1 - 4.0 * k0 * k2, 0.0));
    float q = -0.5 * (k1 + (k1 < 0.0 ? -disc : disc));
    float b = q != 0.0 ? k0 / q : 0.0;
    if (k2 != 0.0 && outside(q / k2) < outside(b)) b = q / k2;
    vec2 s = e + b * g;
    float a = dot(h - b * f, s) / max(dot(s, s), 1e-30);
    uint iu = uint(clamp(floor(a * float(v_cells.y)), 0.0, float(v_cells.y - 1u)));
    uint iv = uint(clamp(floor(b * float(v_cells.z)), 0.0, float(v_cells.z - 1u)));
    item = v_cells.x + iu * v_cells.w + iv + 1u;
}
