#version 330 core
// Ray march of one hypertexture (Perlin and Hoffert 1989) through its 3D density texture:
// emission-absorption with ambient in-scattering, front to back (the model of
// workbench/renderers/raster_volume.py, twin of zbuffer_volume.py).  Output (L, T): blended
// with (ONE, SRC_ALPHA) over what is drawn, the pixel becomes L + T behind.
// Needs: RADIUS, STEP, DENSITY, ALBEDO, EMISSION, SCENE_AMBIENT, N_STOPS, RAMP_D, RAMP_C.
uniform mat4 u_object_from_world;
uniform mat3 u_world_from_camera;  // rotation part
uniform vec3 u_eye;
uniform vec2 u_tan;                // tan(fov_x / 2), tan(fov_y / 2)
uniform vec4 u_viewport;           // x, y, width, height
uniform vec2 u_near_far;
uniform sampler2D u_scene_depth;   // the opaque pass's window depth (1: nothing drawn)
uniform sampler3D u_density;       // D at texel centres tiling [-R, R]^3, [z][y][x]

out vec4 frag_color;

// The ramp's colour at density d: linear between stops, clamped (hypertexture.ramp).
vec3 ramp(float d) {
    const float rd[N_STOPS] = RAMP_D;
    const vec3 rc[N_STOPS] = RAMP_C;
    vec3 c = rc[0];
    for (int i = 1; i < N_STOPS; ++i) {
        float w = rd[i] > rd[i - 1] ? clamp((d - rd[i - 1]) / (rd[i] - rd[i - 1]), 0.0, 1.0)
                                    : (d >= rd[i] ? 1.0 : 0.0);
        c = mix(c, rc[i], w);
    }
    return c;
}

void main() {
    // the pixel centre's ray (Camera.rays): camera frame (x tan_x, y tan_y, -1), unit in world
    vec2 p = (gl_FragCoord.xy - u_viewport.xy) / u_viewport.zw * 2.0 - 1.0;
    vec3 d_cam = vec3(p * u_tan, -1.0);
    float len_cam = length(d_cam);
    vec3 d = u_world_from_camera * (d_cam / len_cam);
    // the opaque surface behind: window depth -> camera depth -> distance along the unit ray
    float wd = texelFetch(u_scene_depth, ivec2(gl_FragCoord.xy), 0).r;
    float n = u_near_far.x, f = u_near_far.y;
    float t_surface = wd >= 1.0 ? 3.0e38 : n * f / (f - wd * (f - n)) * len_cam;
    // object space: O + t D, the bounding sphere |x| < RADIUS (stable roots)
    vec3 O = (u_object_from_world * vec4(u_eye, 1.0)).xyz;
    vec3 D = mat3(u_object_from_world) * d;
    float a = dot(D, D), b = dot(O, D), c = dot(O, O) - RADIUS * RADIUS;
    float disc = b * b - a * c;
    if (disc <= 0.0) discard;
    float q = -(b + (b >= 0.0 ? 1.0 : -1.0) * sqrt(disc));
    float ta = q / a, tb = c / q;
    float t0 = max(min(ta, tb), 0.0), t1 = min(max(ta, tb), t_surface);
    if (!(t1 > t0)) discard;
    float len_D = sqrt(a);
    int steps = max(1, int(ceil((t1 - t0) * len_D / STEP)));
    float h = (t1 - t0) / float(steps);
    float tau_per_density = DENSITY * h * len_D;
    vec3 L = vec3(0.0);
    float T = 1.0;
    for (int j = 0; j < steps; ++j) {
        vec3 x = O + (t0 + (float(j) + 0.5) * h) * D;
        float Dj = texture(u_density, (x + RADIUS) / (2.0 * RADIUS)).r;
        float e = exp(-tau_per_density * Dj);
        vec3 colour = ramp(Dj);
        vec3 albedo = ALBEDO * colour;
        vec3 J = (1.0 - albedo) * EMISSION * colour + albedo * SCENE_AMBIENT;
        L += T * (1.0 - e) * J;
        T *= e;
    }
    frag_color = vec4(L, T);
}
