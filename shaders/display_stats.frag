#version 330 core
// The difference view's statistics on the GPU, one reduction step: output texel (x, y) holds
// the maximum (r) and the sum (g) of the u_block.x by u_block.y block of the input that starts
// at (x, y) * u_block (texels past the input's edge left out).  The first step reads a value
// image (u_first = 1: its r channel is both the value and the sum's term); the next steps
// read the (maximum, sum) pairs of the previous one, down to one texel: the image's maximum
// and sum.  Values are >= 0 (the "abs" map), so 0 starts the maximum.
uniform sampler2D u_value;
uniform ivec2 u_block;
uniform int u_first;
out vec2 f_stats;

void main() {
    ivec2 size = textureSize(u_value, 0);
    ivec2 o = ivec2(gl_FragCoord.xy) * u_block;
    ivec2 stop = min(o + u_block, size);
    float m = 0.0;
    float s = 0.0;
    for (int y = o.y; y < stop.y; ++y) {
        for (int x = o.x; x < stop.x; ++x) {
            vec2 v = texelFetch(u_value, ivec2(x, y), 0).rg;
            m = max(m, v.r);
            s += u_first == 1 ? v.r : v.g;
        }
    }
    f_stats = vec2(m, s);
}
