// Helpers shared by every shader.  Needs: TOL_ZERO.

// Unit vector, or zero for a zero vector (GLSL's normalize(0) is NaN).
vec3 safe_normalize(vec3 v) {
    float len2 = dot(v, v);
    return len2 > TOL_ZERO * TOL_ZERO ? v * inversesqrt(len2) : vec3(0.0);
}
