// Texture evaluation, GLSL mirror of workbench/renderers/texturing.py (read its docstring for
// the formulas; tests compare the two at a few pixels).  Object-space inputs.
// Needs: TOL_ZERO, TOL_BUMP_STEP, HAS_UV_ATTR (const bool) and v_uv (the mesh uv, when a bump map
// uses the uv projection); the *_KIND / *_PROJ defines of the maps in use.
#include "common.glsl"

const float TWO_PI = 6.283185307179586;
const float PI = 3.141592653589793;

// projections (values of TEX_PROJ, BUMP_PROJ, OPACITY_PROJ)
#define PROJ_UV 0
#define PROJ_PLANAR 1
#define PROJ_CYLINDRICAL 2
#define PROJ_SPHERICAL 3
#define PROJ_SOLID 4
// patterns (TEX_KIND; OPACITY_KIND uses K_GRID and K_CHECKER)
#define K_CHECKER 1
#define K_BRICKS 2
#define K_MARBLE 3
#define K_WOOD 4
#define K_GRID 5
#define K_IMAGE 6
#define K_NOISE 7
#define K_WAVES 8
#define K_CONSTANT 9

// A mapping: centre, pole Sp, equator Se (orthogonal to Sp), W = Sp x Se, scale, line width.
struct Mapping {
    vec3 center;
    vec3 sp;
    vec3 se;
    vec3 w;
    float scale;
    float width;
};

float wrap01(float u) {
    u = u - floor(u);
    return u >= 1.0 ? 0.0 : u;
}

// u = atan2(-d.W, -d.Se) / 2pi in [0, 1), increasing eastward (counter-clockwise seen from the
// pole, DESIGN errata 8); 0 on the axis.
float longitude(vec3 d, Mapping m) {
    float x = -dot(d, m.se);
    float y = -dot(d, m.w);
    bool on_axis = x * x + y * y <= TOL_ZERO * TOL_ZERO * max(1.0, dot(d, d));
    return wrap01(on_axis ? 0.0 : atan(y, x) / TWO_PI);
}

vec2 project_planar(Mapping m, vec3 d) {
    return vec2(dot(d, m.se), dot(d, m.w));
}

vec2 project_cylindrical(Mapping m, vec3 d) {
    return vec2(longitude(d, m), dot(d, m.sp));
}

vec2 project_spherical(Mapping m, vec3 d) {
    float h = dot(d, m.sp);
    float rho = length(d - h * m.sp);
    float phi = (rho == 0.0 && h == 0.0) ? 0.0 : atan(rho, -h);
    return vec2(longitude(d, m), phi / PI);
}

// (u, v) before scale of object point P under projection PROJ (a literal define, so that the
// compiler keeps one branch); uv is the mesh's, used by PROJ_UV when HAS_UV_ATTR, else the
// spherical fallback.
#define PROJECT(PROJ, m, P, uv) ((PROJ) == PROJ_UV && HAS_UV_ATTR ? (uv) \
    : (PROJ) == PROJ_PLANAR ? project_planar(m, (P) - m.center) \
    : (PROJ) == PROJ_CYLINDRICAL ? project_cylindrical(m, (P) - m.center) \
    : project_spherical(m, (P) - m.center))

// Pattern coordinates s: scale * (u, v, 0), or scale * (P - center) for the solid projection.
#define PATTERN_COORDS(PROJ, m, P, uv) ((PROJ) == PROJ_SOLID ? m.scale * ((P) - m.center) \
    : vec3(m.scale * PROJECT(PROJ, m, P, uv), 0.0))

// ---------------------------------------------------------------- noise (lowbias32 value noise)
#include "hash.glsl"

vec3 quintic(vec3 t) {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

float value_noise(vec3 p) {
    vec3 fl = floor(p);
    vec3 f = p - fl;
    ivec3 i = ivec3(fl);
    vec3 w = quintic(f);
    float out_ = 0.0;
    for (int dx = 0; dx < 2; ++dx)
        for (int dy = 0; dy < 2; ++dy)
            for (int dz = 0; dz < 2; ++dz) {
                float wgt = (dx == 1 ? w.x : 1.0 - w.x) * (dy == 1 ? w.y : 1.0 - w.y)
                          * (dz == 1 ? w.z : 1.0 - w.z);
                out_ += wgt * hash3(i + ivec3(dx, dy, dz));
            }
    return out_;
}

float fbm(vec3 p) {
    float out_ = 0.0;
    float s = 1.0;
    for (int k = 0; k < 4; ++k) {
        out_ += (value_noise(p * s) - 0.5) / s;
        s *= 2.0;
    }
    return out_;
}

float turbulence(vec3 p) {
    float out_ = 0.0;
    float s = 1.0;
    for (int k = 0; k < 4; ++k) {
        out_ += abs(2.0 * value_noise(p * s) - 1.0) / (2.0 * s);
        s *= 2.0;
    }
    return out_;
}

// ---------------------------------------------------------------- patterns
float mortar_distance(vec3 s) {
    vec2 b = vec2(s.x + s.z, s.y);
    float row = floor(b.y / 0.5);
    float x = b.x + 0.5 * (row - 2.0 * floor(row / 2.0));
    float fx = x - floor(x);
    float fy = b.y / 0.5 - row;
    return min(min(fx, 1.0 - fx), 0.5 * min(fy, 1.0 - fy));
}

// Blend weights of colors[1] (see texturing.pattern_value), one function per pattern.
float checker(vec3 s) {
    vec3 fl = floor(s);
    float parity = fl.x + fl.y + fl.z;
    return parity - 2.0 * floor(parity / 2.0);
}

float bricks(vec3 s, float width) {
    return mortar_distance(s) < 0.5 * width ? 1.0 : 0.0;
}

float grid(vec3 s, float width) {
    vec2 f = s.xy - floor(s.xy);
    return min(f.x, f.y) < width ? 1.0 : 0.0;
}

float marble(vec3 s) {
    return 0.5 + 0.5 * sin(TWO_PI * (s.x + 2.0 * turbulence(s)));
}

float wood(vec3 s, bool solid) {
    float r = solid ? length(s.xz) : length(s.xy);
    float t = 4.0 * (r + 0.3 * fbm(s));
    return smoothstep(0.0, 0.8, t - floor(t));
}

// Bilinear lookup, v = 0 at the image's bottom row (images are uploaded bottom row first).
vec4 sample_image(sampler2D img, vec2 uv) {
    return texture(img, uv);
}

const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);

// ---------------------------------------------------------------- colour texture
#ifdef TEX_KIND
const Mapping m_tex = TEX_MAPPING;   // literals (raster_shaders.material_defines)
#if TEX_KIND == K_IMAGE
uniform sampler2D u_tex_image;
#endif

vec3 texture_color(vec3 P, vec2 uv) {
#if TEX_KIND == K_IMAGE
    return sample_image(u_tex_image, PROJECT(TEX_PROJ, m_tex, P, uv) * m_tex.scale).rgb;
#else
    vec3 s = PATTERN_COORDS(TEX_PROJ, m_tex, P, uv);
#if TEX_KIND == K_CHECKER
    float t = checker(s);
#elif TEX_KIND == K_BRICKS
    float t = bricks(s, m_tex.width);
#elif TEX_KIND == K_GRID
    float t = grid(s, m_tex.width);
#elif TEX_KIND == K_MARBLE
    float t = marble(s);
#else
    float t = wood(s, TEX_PROJ == PROJ_SOLID);
#endif
    return mix(TEX_COLOR0, TEX_COLOR1, t);
#endif
}
#endif

// ---------------------------------------------------------------- bump
#ifdef BUMP_KIND
const Mapping m_bump = BUMP_MAPPING;
uniform mat3 u_grad_from_object;   // M^-T: object-space gradient -> world-space gradient
#if BUMP_KIND == K_IMAGE
uniform sampler2D u_bump_image;
#endif

float bump_height(vec3 P) {
#if BUMP_KIND == K_IMAGE
    return dot(sample_image(u_bump_image, PROJECT(BUMP_PROJ, m_bump, P, v_uv) * m_bump.scale).rgb, LUMA);
#else
    vec3 s = PATTERN_COORDS(BUMP_PROJ, m_bump, P, v_uv);
#if BUMP_KIND == K_BRICKS
    float hw = 0.5 * m_bump.width;
    return smoothstep(0.5 * hw, 1.5 * hw, mortar_distance(s));
#elif BUMP_KIND == K_NOISE
    return 0.5 + fbm(s);
#else
    return 0.5 + 0.25 * (sin(TWO_PI * s.x) + sin(TWO_PI * s.y));
#endif
#endif
}

// Perturbed unit world normal (texturing.bump_normal): N' = normalize(N - tangential grad d),
// grad d by forward differences along the object axes.
vec3 bump_normal(vec3 P, vec3 Nw) {
    float delta = TOL_BUMP_STEP / m_bump.scale;
    float h0 = bump_height(P);
    vec3 g = vec3(bump_height(P + vec3(delta, 0.0, 0.0)), bump_height(P + vec3(0.0, delta, 0.0)),
                  bump_height(P + vec3(0.0, 0.0, delta)));
    g = (g - h0) / delta;
    g *= BUMP_STRENGTH / m_bump.scale;
    vec3 gw = u_grad_from_object * g;
    vec3 gt = gw - dot(gw, Nw) * Nw;
    vec3 Np = safe_normalize(Nw - gt);
    return dot(Np, Np) > 0.0 ? Np : Nw;
}
#endif

// ---------------------------------------------------------------- opacity
#ifdef OPACITY_KIND
const Mapping m_op = OPACITY_MAPPING;
#if OPACITY_KIND == K_IMAGE
uniform sampler2D u_op_image;
#endif

float opacity(vec3 P, vec2 uv) {
#if OPACITY_KIND == K_CONSTANT
    return OPACITY_VALUE;
#elif OPACITY_KIND == K_IMAGE
    vec4 c = sample_image(u_op_image, PROJECT(OPACITY_PROJ, m_op, P, uv) * m_op.scale);
    return OPACITY_HAS_ALPHA > 0.5 ? c.a : dot(c.rgb, LUMA);
#else
    vec3 s = PATTERN_COORDS(OPACITY_PROJ, m_op, P, uv);
#if OPACITY_KIND == K_GRID
    return grid(s, m_op.width);
#else
    return 1.0 - checker(s);
#endif
#endif
}
#endif

// ---------------------------------------------------------------- environment
#ifdef ENV_KIND
#if ENV_KIND == 2
uniform sampler2D u_env_image;
#else
uniform vec3 u_env_zenith;
uniform vec3 u_env_horizon;
uniform vec3 u_env_ground;
#endif

vec3 environment(vec3 dir) {
    vec3 d = safe_normalize(dir);
#if ENV_KIND == 2
    bool vertical = d.x * d.x + d.z * d.z <= TOL_ZERO * TOL_ZERO;
    float u = wrap01(0.5 + (vertical ? 0.0 : atan(d.x, -d.z)) / TWO_PI);
    float v = 0.5 + asin(clamp(d.y, -1.0, 1.0)) / PI;
    return texture(u_env_image, vec2(u, v)).rgb;
#else
    float y = d.y;
    return y >= 0.0 ? mix(u_env_horizon, u_env_zenith, clamp(y, 0.0, 1.0))
                    : mix(u_env_horizon, u_env_ground, clamp(-4.0 * y, 0.0, 1.0));
#endif
}
#endif
