// Live variants (raster_shaders.material_defines, drawn while a slider edits the values): the
// material's MAT_* names are these uniforms (LIVE_MATERIAL), the lights' positions and colours
// in FOR_EACH_LIGHT read these arrays (LIVE_LIGHTS).  Included by lighting.glsl and by
// standins.glsl (whose environment lookups read MAT_KR), whichever comes first.
#ifdef LIVE_MATERIAL
uniform vec3 u_mat_color;
uniform vec3 u_mat_emission;
uniform float u_mat_ka;
uniform float u_mat_kd;
uniform float u_mat_ks;
uniform float u_mat_kr;
uniform float u_mat_shininess;
#endif
#ifdef LIVE_LIGHTS
uniform vec3 u_light_pos[N_LIGHTS];
uniform vec3 u_light_color[N_LIGHTS];
#endif
