#version 330
// Item buffer: the nearest surface's patch number + 1 where its front face is seen, 0 where
// nothing or a back face is (a back face still hides what is behind it).
flat in uint v_id;
in float v_depth;
out uint item;

void main() {
    gl_FragDepth = v_depth;
    item = gl_FrontFacing ? v_id + 1u : 0u;
}
