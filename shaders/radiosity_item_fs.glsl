#version 330
// Item buffer: the nearest surface's patch number + 1 where its front face is seen, 0 where
// nothing or a back face is (a back face still hides what is behind it).  The patch of
// triangle gl_PrimitiveID of this draw is looked up in tri_patch (row-major, TRI_ROW
// texels per row), written with the index buffer.
#define TRI_ROW 4096
uniform usampler2D tri_patch;
in float v_depth;
out uint item;

void main() {
    gl_FragDepth = v_depth;
    ivec2 t = ivec2(gl_PrimitiveID % TRI_ROW, gl_PrimitiveID / TRI_ROW);
    item = gl_FrontFacing ? texelFetch(tri_patch, t, 0).r + 1u : 0u;
}
