// Oren-Nayar diffuse reflection: rough surfaces of V-shaped facets with Gaussian slopes of
// standard deviation sigma (radians).  Qualitative model of
//   M. Oren and S. K. Nayar, "Generalization of Lambert's Reflectance Model", SIGGRAPH 1994, eq. 30:
//   L_r = kd C cos(theta_i) (A + B max(0, cos(phi_i - phi_r)) sin(alpha) tan(beta))
//   A = 1 - 0.5 sigma^2 / (sigma^2 + 0.33),  B = 0.45 sigma^2 / (sigma^2 + 0.09),
//   alpha = max(theta_i, theta_r),  beta = min(theta_i, theta_r).
// sigma = 0 gives A = 1, B = 0: Lambert's kd C max(N.L, 0).  No specular term (ks unused).
//
// Use: workbench render whitted -m glsl:examples/shading/oren_nayar.glsl --set roughness=0.5 -o on.png
#pragma parameter roughness 0.3 facet slope deviation sigma in radians (0: Lambert)

vec3 shade(vec3 P, vec3 N, vec3 V, vec3 L, Material m) {
    float cos_i = dot(N, L);
    if (cos_i <= 0.0) return vec3(0.0);
    float cos_r = clamp(dot(N, V), 0.0, 1.0);
    float s2 = roughness * roughness;
    float A = 1.0 - 0.5 * s2 / (s2 + 0.33);
    float B = 0.45 * s2 / (s2 + 0.09);
    // cos(phi_i - phi_r): the angle between L and V projected on the tangent plane
    float cos_phi = dot(safe_normalize(L - N * cos_i), safe_normalize(V - N * cos_r));
    // sin(alpha) tan(beta): alpha is the larger angle (the smaller cosine)
    float cos_alpha = min(cos_i, cos_r);
    float cos_beta = max(cos_i, cos_r);
    float sin_alpha = sqrt(max(0.0, 1.0 - cos_alpha * cos_alpha));
    float tan_beta = sqrt(max(0.0, 1.0 - cos_beta * cos_beta)) / max(cos_beta, TOL_ZERO);
    return m.kd * m.color * cos_i * (A + B * max(0.0, cos_phi) * sin_alpha * tan_beta);
}
