// Toon (cel) shading: the Lambert term quantised to a few flat bands and a hard-edged
// highlight, as in A. Lake et al., "Stylized Rendering Techniques for Scalable Real-Time 3D
// Animation", NPAR 2000 (a 1D ramp of the diffuse term).  One light gives at most
// 2 (bands + 1) colours on a plain surface: band levels 0, 1/bands, ..., 1, highlight on or off.
//
// Use: workbench render whitted -m glsl:examples/shading/toon.glsl --set bands=3 -o toon.png
#pragma parameter bands 4 number of diffuse bands (>= 1)
#pragma parameter highlight 0.5 Phong term (R.V)^n above which the highlight shows

vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) {
    float n_bands = max(1.0, floor(bands));
    float d = max(dot(N, L), 0.0);
    float level = ceil(d * n_bands) / n_bands;  // 0 where unlit, else 1/bands .. 1
    vec3 color = m.kd * m.color * level;
    if (d > 0.0 && m.ks > 0.0) {
        float phong = pow(clamp(dot(reflect(-L, N), V), 0.0, 1.0), max(m.shininess, 1.0));
        color += m.ks * step(highlight, phong) * vec3(1.0);
    }
    return color;
}
