// The raster family's stand-ins for global effects (workbench/renderers/raster_standins.py):
// dynamic environment maps (ENV_CUBE) and shadow maps (SHADOW_MAPS, Williams 1978).  Both
// store cube maps as tiles of one 2D texture, face f = 0..5 looking along +x, -x, +y, -y, +z,
// -z (cube_face); each tile was drawn with the clip matrix the lookup uses, so the lookup needs
// no cube-map convention.
// Needs: TOL_ZERO (common.glsl).
#include "common.glsl"
#include "live_values.glsl"

#if defined(ENV_CUBE) || defined(SHADOW_MAPS)
// The face of a cube map centred at the origin that direction d crosses (major axis).
int cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0 : 1;
    if (a.y >= a.z) return d.y >= 0.0 ? 2 : 3;
    return d.z >= 0.0 ? 4 : 5;
}

// Normalised device x, y of direction d on its face (cube_face), and m = d.F, its distance
// along the face's axis F: the 90-degree cameras of raster_standins.FACES (look_at with those
// up vectors) see camera x = d.r, y = d.u, depth d.F, with (r, u) per face
// +x: (z, y), -x: (-z, y), +y: (x, z), -y: (-x, z), +z: (-x, y), -z: (x, y).  Computed from
// the components instead of reading each face's matrix per fragment (llvmpipe pays for
// dynamically indexed uniforms).
vec2 cube_ndc(vec3 d, int face, out float m) {
    float s = (face == 0 || face == 2 || face == 5) ? 1.0 : -1.0;
    vec3 a = abs(d);
    vec2 q;
    if (face < 2) {
        m = a.x;
        q = vec2(s * d.z, d.y);
    } else if (face < 4) {
        m = a.y;
        q = vec2(s * d.x, d.z);
    } else {
        m = a.z;
        q = vec2(s * d.x, d.y);
    }
    return q / max(m, TOL_ZERO);
}
#endif

#ifdef ENV_CUBE
// The object's cube map, rendered from its centre c each frame: 3 x 2 tiles of ENV_RES^2
// texels (face f at column f % 3, row f / 3) of radiance and of depth, its faces' clip
// matrices, its centre and its faces' (near, far).
uniform sampler2D u_env_cube;
uniform sampler2D u_env_depth;
uniform vec3 u_env_centre;
uniform vec2 u_env_range;

// Texture coordinates of unit direction dir (from c) in the atlas (the half-texel clamp keeps
// the bilinear filter inside the face's tile); m: dir's component along its face's axis.
vec2 env_uv(vec3 dir, out float m) {
    int face = cube_face(dir);
    float h = 0.5 / float(ENV_RES);
    vec2 uv = clamp(cube_ndc(dir, face, m) * 0.5 + 0.5, vec2(h), vec2(1.0 - h));
    vec2 tile = vec2(float(face - 3 * (face / 3)), float(face / 3));
    return (tile + uv) / vec2(3.0, 2.0);
}

// Distance from c to the surface the map sees in unit direction dir: the window depth w of
// its face gives the depth along the face's axis z = n f / (f - w (f - n)), and the distance
// is z / m (m = dir's component along that axis); the background gives about f.
float env_distance(vec3 dir) {
    float m;
    float w = textureLod(u_env_depth, env_uv(dir, m), 0.0).r;
    float n = u_env_range.x, fa = u_env_range.y;
    return n * fa / (fa - w * (fa - n)) / max(m, TOL_ZERO);
}

// Radiance the ray P + t D (t > 0) meets, looked up in the map with parallax correction by
// distance impostors (Szirmay-Kalos, Aszodi, Lazanyi and Premecz 2005, "Approximate
// ray-tracing on the GPU with distance impostors"): with x = P - c, guess the hit
// x + t D, read the map's distance r in its direction, and move t to where |x + t D| = r
// (t = -x.D + sqrt((x.D)^2 - |x|^2 + r^2)); ENV_ITERATIONS steps from t = r(D).  Without
// them (ENV_ITERATIONS 0) the world is seen from c, not from P (parallax).  The object never
// sees itself (it is not in its own map).
vec3 env_ray(vec3 P, vec3 D) {
    vec3 x = P - u_env_centre;
    vec3 dir = D;
    float b = dot(x, D);
    float xx = dot(x, x);
    for (int i = 0; i < ENV_ITERATIONS; ++i) {
        float r = env_distance(safe_normalize(dir));
        float t = -b + sqrt(max(b * b - xx + r * r, 0.0));
        dir = x + max(t, 0.0) * D;
    }
    float m;
    return textureLod(u_env_cube, env_uv(safe_normalize(dir), m), 0.0).rgb;
}

#ifdef ENV_KT
// The direction a ray entering the object at P along T1 leaves it, the object taken as the
// sphere through P about the map's centre c (exact for a sphere): the chord P + t T1 with
// t = -2 T1.(P - c) meets it again at Q, where the ray refracts out (Snell's law with
// ior^-1, normal (Q - c) / |Q - c|); total internal reflection (a negative radicand, which a
// sphere never gives but another shape may) reflects it instead (DESIGN errata 5).
vec3 exit_direction(vec3 P, vec3 T1) {
    vec3 Q = P - 2.0 * dot(T1, P - u_env_centre) * T1;  // (env_terms starts the ray there)
    vec3 N2 = safe_normalize(Q - u_env_centre);
    vec3 T2 = refract(T1, -N2, MAT_IOR);
    return dot(T2, T2) > 0.0 ? T2 : reflect(T1, -N2);
}
#endif

// The stand-in's global terms at a surface point P seen along -S with unit normal N (facing
// the viewer): kr env(R), R = 2 (N.S) N - S (the mirror direction); ENV_KT: kt C env(T2), T2
// the direction leaving the object after refracting in at P (T1 = refract(-S, N, 1 / ior);
// entering a denser medium never reflects totally) and out again (exit_direction).  Seen
// from inside (inside: the viewer is on the inner side of the surface, the object's outward
// normal points away from it) the ray leaves the object at P: T = refract(-S, N, ior), or
// the mirror direction on total internal reflection (DESIGN errata 5).
vec3 env_terms(vec3 P, vec3 N, vec3 S, vec3 C, bool inside) {
    vec3 g = MAT_KR * env_ray(P, 2.0 * dot(N, S) * N - S);
#ifdef ENV_KT
    if (inside) {
        vec3 T = refract(-S, N, MAT_IOR);
        g += MAT_KT * C * env_ray(P, dot(T, T) > 0.0 ? T : 2.0 * dot(N, S) * N - S);
        return g;
    }
    vec3 T1 = refract(-S, N, 1.0 / MAT_IOR);
    if (dot(T1, T1) > 0.0) {
        vec3 Q = P - 2.0 * dot(T1, P - u_env_centre) * T1;
        g += MAT_KT * C * env_ray(Q, exit_direction(P, T1));
    } else {
        g += MAT_KT * C * env_ray(P, -S);
    }
#endif
    return g;
}
#endif

#ifdef SHADOW_MAPS
// Shadow maps (Williams 1978): one tile of SHADOW_RES^2 depths per directional light
// (orthographic) and six per point light (a cube), in one depth texture of SHADOW_COLS
// tiles per row.  SHADOW_BASE[k]: first tile of light k; SHADOW_CUBE[k]: a point light;
// SHADOW_POS[k]: its position (or the direction towards a directional light); SHADOW_RANGE[k]:
// a point light's cube faces' (near, far); SHADOW_BIAS: the world distance a receiver is moved
// towards the light and along its normal before the depth test (the normal offset keeps
// surfaces lit at grazing angles, where a depth map's texel spans a long stretch of depth, from
// shadowing themselves; too small: acne; too large: shadows detach, "peter panning").
// SHADOW_LIVE (the live-lights variant, drawn while a light is being moved): the positions and
// ranges, which follow the lights, are uniforms (the maps are redrawn, the program kept).
uniform sampler2D u_shadow_atlas;
uniform mat4 u_shadow_clip[SHADOW_TILES];
const int SHADOW_BASE[N_LIGHTS] = SHADOW_BASE_LIST;
const bool SHADOW_CUBE[N_LIGHTS] = SHADOW_CUBE_LIST;
#ifdef SHADOW_LIVE
uniform vec3 u_shadow_pos[N_LIGHTS];
uniform vec2 u_shadow_range[N_LIGHTS];
#define SHADOW_POS u_shadow_pos
#define SHADOW_RANGE u_shadow_range
#else
const vec3 SHADOW_POS[N_LIGHTS] = SHADOW_POS_LIST;
const vec2 SHADOW_RANGE[N_LIGHTS] = SHADOW_RANGE_LIST;
#endif

// 1 where light k reaches P (unit shading normal N, towards the viewer: the side a light
// that counts lights) when the depth stored in its map is not nearer than P, else 0.  One
// point sample, no filtering: the map's texels show as jagged shadow edges (aliasing).
float shadow_visibility(int k, vec3 P, vec3 N) {
    vec3 towards = SHADOW_CUBE[k] ? SHADOW_POS[k] - P : SHADOW_POS[k];
    vec3 Pb = P + SHADOW_BIAS * (safe_normalize(towards) + N);
    int tile = SHADOW_BASE[k];
    vec3 ndc;
    if (SHADOW_CUBE[k]) {
        // the face's perspective (gluPerspective, 90 degrees): z_ndc = (f + n) / (f - n)
        // - 2 f n / ((f - n) m) at distance m along the face's axis
        vec3 d = Pb - SHADOW_POS[k];
        int face = cube_face(d);
        float m;
        ndc.xy = cube_ndc(d, face, m);
        float n = SHADOW_RANGE[k].x, f = SHADOW_RANGE[k].y;
        ndc.z = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * max(m, TOL_ZERO));
        tile += face;
    } else {
        vec4 c = u_shadow_clip[tile] * vec4(Pb, 1.0);  // orthographic: w = 1
        ndc = c.xyz;
    }
    if (abs(ndc.x) > 1.0 || abs(ndc.y) > 1.0 || ndc.z > 1.0) return 1.0;
    ivec2 texel = clamp(ivec2(floor((ndc.xy * 0.5 + 0.5) * float(SHADOW_RES))), ivec2(0),
                        ivec2(SHADOW_RES - 1));
    ivec2 origin = SHADOW_RES * ivec2(tile - SHADOW_COLS * (tile / SHADOW_COLS), tile / SHADOW_COLS);
    float stored = texelFetch(u_shadow_atlas, origin + texel, 0).r;
    return ndc.z * 0.5 + 0.5 <= stored ? 1.0 : 0.0;
}
#endif
