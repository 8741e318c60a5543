// The specular cone of a pixel: Lv(p, w_s, a_s) along w_s = 2 (w_o . n) n - w_o, with the
// aperture of the normalized Blinn-Phong lobe of exponent 2/r^4 - 2 (lib/brdf.glsl). Traced
// at the anchor pixels (even x and y) and where it is too narrow to share; the pixels between
// anchors take it from the anchors like them (cone_trace/share_anchor_cones.comp). A lobe as
// wide as the hemisphere traces none: it takes what the diffuse layer takes
// (hemisphere_reflectance).
#include "lib/gbuffer.glsl"
#include "lib/cone.glsl"
#include "lib/brdf.glsl"
#include "lib/environment.glsl"
#include "lib/camera.glsl"

layout(binding = IMG_SPECULAR_IN, rgba32f) uniform image2D specular_in;  // per anchor: Lv

// Lv(p, w_s, a_s) of surface s: what the cone gathers through the voxels, and the sky beyond
// them seen through what it did not meet.
vec3 specular_incoming(Surface s) {
    vec3 wo = to_camera(s.position);
    vec3 ws = 2.0 * max(dot(wo, s.normal), 0.0) * s.normal - wo;
    float tan_half_angle = specular_tan_half_angle(s.roughness);
    vec4 cone = trace_cone(s.position, s.normal, surface_level(s.position), ws, tan_half_angle, 1e9, SPECULAR_READING);
    return cone.rgb + (1.0 - min(cone.a, 1.0)) * environment_radiance(ws, atan(tan_half_angle));
}

// What the specular layer of surface s reflects towards the camera of the light its cone
// gathers: its directional albedo at w_o (lib/brdf.glsl specular_layer_albedo).
vec3 specular_reflectance(Surface s) {
    vec3 f0 = specular_f0(s.albedo, s.metalness, s.dielectric_f0);
    return specular_layer_albedo(f0, s.roughness, max(dot(to_camera(s.position), s.normal), 0.0));
}

// The diffuse layer's albedo of surface s seen from the camera, (1 - m) k_d (1 - F(w_o . n)).
vec3 diffuse_albedo(Surface s) {
    return diffuse_layer_albedo(s.albedo, s.metalness, s.dielectric_f0, dot(to_camera(s.position), s.normal));
}

// Whether surface s traces a specular cone: it has a specular layer whose lobe is narrower than
// the hemisphere (hemisphere_lobe).
bool traces_specular_cone(Surface s) {
    return has_specular_layer(specular_f0(s.albedo, s.metalness, s.dielectric_f0)) && !hemisphere_lobe(s.roughness);
}

// What surface s reflects towards the camera of the light that arrives from every direction
// (the diffuse cones' gather, the sky's and the emitters' light): the diffuse layer's albedo
// where `diffuse`, plus, where `specular` and its lobe spans the hemisphere, the specular
// layer's directional albedo A(w_o).
vec3 hemisphere_reflectance(Surface s, bool diffuse, bool specular) {
    vec3 reflectance = diffuse ? diffuse_albedo(s) : vec3(0.0);
    if (specular && hemisphere_lobe(s.roughness)) reflectance += specular_reflectance(s);
    return reflectance;
}
