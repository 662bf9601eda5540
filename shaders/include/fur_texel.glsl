// The fur's texel (Kajiya and Kay 1989), GLSL twin of workbench/scene/kinds/fur.py (density,
// texel) and fur_kernels.py (texel, kajiya_kay); the definitions are in fur.py's docstring.
// Needs: BASE_BOX (1: box, 0: sphere), SIZE (vec3: the radius thrice, or the half-sizes),
// LENGTH, CELL (1 / sqrt(strands)), THICKNESS, KS, SHININESS.
#include "hash.glsl"

// (signed distance to the base, foot point) of an object-space point outside or on the base.
vec4 fur_project(vec3 x) {
#if BASE_BOX
    vec3 q = abs(x) - SIZE;
    float s = length(max(q, vec3(0.0))) + min(max(q.x, max(q.y, q.z)), 0.0);
    return vec4(s, clamp(x, -SIZE, SIZE));
#else
    float r = length(x);
    return vec4(r - SIZE.x, x * (SIZE.x / max(r, 1.0e-30)));
#endif
}

// D(x) in {0, 1}; T the strand's unit tangent (object space, from the foot point) where D = 1.
float fur_texel(vec3 x, out vec3 T) {
    T = vec3(0.0);
    vec4 sf = fur_project(x);
    float s = sf.x;
    vec3 foot = sf.yzw;
    if (s < 0.0 || s > LENGTH) return 0.0;
    float r_max = THICKNESS * (1.0 - s / LENGTH);
    ivec3 base = ivec3(floor(foot / CELL));
    float best = 3.0e38;
    for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b)
            for (int e = -1; e <= 1; ++e) {
                ivec3 c = base + ivec3(a, b, e);
                vec3 root = (vec3(c) + vec3(hash3(c), hash3(c + ivec3(1013, 0, 0)), hash3(c + ivec3(0, 2027, 0))))
                            * CELL;
                best = min(best, distance(foot, fur_project(root).yzw));
            }
    if (!(best < r_max)) return 0.0;
    vec3 v = x - foot;
    float n = length(v);
    T = n > 0.0 ? v / n : vec3(0.0);
    return 1.0;
}

// Per unit light: (sin(T, L), ks max(0, cos phi)^shininess), cos phi = (T.L)(T.d) + sin(T, L)
// sin(T, d), d the view ray's direction (fur_kernels.kajiya_kay; x^0 = 1 for x > 0).
vec2 kajiya_kay(vec3 T, vec3 L, vec3 d) {
    float tl = dot(T, L), td = dot(T, d);
    float sl = sqrt(max(0.0, 1.0 - tl * tl)), sd = sqrt(max(0.0, 1.0 - td * td));
    float c = tl * td + sl * sd;
    float spec = c > 0.0 ? KS * (SHININESS == 0.0 ? 1.0 : pow(c, SHININESS)) : 0.0;
    return vec2(sl, spec);
}
