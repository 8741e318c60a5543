// Reflectance models: Lambert diffuse and the normalized Blinn-Phong specular lobe.
#include "engine_constants.glsl"

// Blinn-Phong exponent of roughness r: s = 2 / r^4 - 2 (the lecture's mapping).
float blinn_phong_exponent(float roughness) {
    float r4 = pow(max(roughness, 0.05), 4.0);
    return max(2.0 / r4 - 2.0, 0.0);
}

// Schlick's approximation of the Fresnel reflectance.
vec3 fresnel_schlick(vec3 f0, float cos_theta) {
    return f0 + (1.0 - f0) * pow(1.0 - clamp(cos_theta, 0.0, 1.0), 5.0);
}

// Specular reflectance at normal incidence: the dielectric's F0, or the albedo for metals.
vec3 specular_f0(vec3 albedo, float metalness, float dielectric_f0) {
    return mix(vec3(dielectric_f0), albedo, metalness);
}

// Specular cone aperture from the normalized Blinn-Phong lobe of exponent s = 2/r^4 - 2:
// sigma^2 = c r^4 / (1 - r^4) with c = 2 (the lobe around w_s is twice as wide as around h),
// sin(a/2) = sigma, tan(a/2) = sqrt(sigma^2 / (1 - sigma^2)); r = 0 gives the one-voxel
// mirror cone (the marcher floors the diameter at a voxel), r = 1 a hemisphere.
float specular_tan_half_angle(float roughness) {
    float r4 = pow(roughness, 4.0);
    if (r4 >= 1.0) return 1e4;
    float sigma2 = min(2.0 * r4 / (1.0 - r4), 1.0);
    return sigma2 >= 1.0 ? 1e4 : sqrt(sigma2 / (1.0 - sigma2));
}

// Whether a surface with this F0 has a specular layer at all (F0 = 0: Lambert alone).
bool has_specular_layer(vec3 f0) {
    return any(greaterThan(f0, vec3(0.0)));
}

// Hemispherical albedo of the specular layer: Schlick's F averaged over the cosine-weighted
// hemisphere, F0 + (1 - F0) 2 int (1 - mu)^5 mu dmu = F0 + (1 - F0) / 21; none without one (F0 = 0).
vec3 specular_albedo(vec3 f0) {
    return has_specular_layer(f0) ? f0 + (1.0 - f0) / 21.0 : vec3(0.0);
}

// BRDF times pi-free cosine-less form: f(l, v) = (1 - m) k_d / pi + F (s + 2) / (8 pi) (n.h)^s.
vec3 brdf(vec3 n, vec3 l, vec3 v, vec3 albedo, float roughness, float metalness, float dielectric_f0) {
    vec3 diffuse = (1.0 - metalness) * albedo / PI;
    vec3 f0 = specular_f0(albedo, metalness, dielectric_f0);
    if (all(equal(f0, vec3(0.0)))) return diffuse;
    vec3 h = normalize(l + v);
    float s = blinn_phong_exponent(roughness);
    float normalization = (s + 2.0) / (8.0 * PI); // normalized Blinn-Phong
    return diffuse + fresnel_schlick(f0, dot(l, h)) * normalization * pow(max(dot(n, h), 0.0), s);
}
