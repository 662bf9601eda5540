// The material a user's shading model receives (user_model.glsl; the workbench's material
// fields of workbench/scene/model.py, C with its texture applied).
struct Material {
    vec3 color;      // C: the material's colour times its texture
    vec3 emission;   // E (added by the workbench, not by shade())
    float ka;        // ambient coefficient (ka C Ia added by the workbench)
    float kd;        // diffuse coefficient
    float ks;        // specular coefficient
    float shininess; // specular exponent n
    float kr;        // mirror reflection coefficient (environment maps only)
};
