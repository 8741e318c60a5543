// The reflectance model: glTF 2.0's metallic-roughness BRDF (specification, Appendix B) with the
// lecture's normalized Blinn-Phong lobe in place of GGX:
//   f(l, v) = (1 - F(n.v)) c_diff / pi + F(v.h) D(h) Vis(l, v),  c_diff = (1 - m) k_d,
//   F0 = mix(dielectric F0, k_d, m), D = (s + 2) / (2 pi) (n.h)^s, s = 2 / r^4 - 2,
//   Vis = G1(n.l) G1(n.v) / (4 n.l n.v), Smith's masking of the Beckmann lobe of alpha = r^2,
//   the lobe this Blinn-Phong one approximates (alpha^2 = 2 / (s + 2)).
// The diffuse layer is weighted by the Fresnel reflectance of the view direction, 1 - F(n.v),
// where glTF's fresnel_mix takes 1 - F(v.h) per light direction: that lets a surface seen at
// grazing angles reflect more than it receives, this keeps the two layers within it, and
// cones, which gather light from many directions at once, can weigh their light by it. A
// dielectric F0 of 0 means no specular layer: Lambert alone.
#include "engine_constants.glsl"

// Blinn-Phong exponent of roughness r: s = 2 / r^4 - 2 (the lecture's mapping).
float blinn_phong_exponent(float roughness) {
    float r4 = pow(max(roughness, MIN_ROUGHNESS), 4.0);
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

// The width of the normalized Blinn-Phong lobe of exponent s = 2/r^4 - 2 around w_s:
// sigma^2 = c r^4 / (1 - r^4) with c = 2 (the lobe around w_s is twice as wide as around h),
// at most 1, which it reaches at r^4 = 1/3 (r = 0.76): a lobe as wide as the hemisphere.
float specular_lobe_sigma2(float roughness) {
    float r4 = pow(roughness, 4.0);
    return r4 >= 1.0 / 3.0 ? 1.0 : 2.0 * r4 / (1.0 - r4);
}

// Whether the specular lobe of roughness r spans the hemisphere (sigma^2 = 1): it weighs the
// light arriving from every direction nearly alike, and takes it as the diffuse layer does
// (lib/specular_cone.glsl hemisphere_reflectance) where a single cone that wide along w_s
// would read the grid's coarsest cell.
bool hemisphere_lobe(float roughness) {
    return specular_lobe_sigma2(roughness) >= 1.0;
}

// Specular cone aperture of a lobe narrower than the hemisphere: sin(a/2) = sigma,
// tan(a/2) = sqrt(sigma^2 / (1 - sigma^2)); r = 0 gives the one-voxel mirror cone (the marcher
// floors the diameter at a voxel).
float specular_tan_half_angle(float roughness) {
    float sigma2 = specular_lobe_sigma2(roughness);
    return sqrt(sigma2 / (1.0 - sigma2));
}

// Whether a surface with this F0 has a specular layer at all (F0 = 0: Lambert alone).
bool has_specular_layer(vec3 f0) {
    return any(greaterThan(f0, vec3(0.0)));
}

// The specular layer's Fresnel reflectance at cos_theta, zero without one.
vec3 layer_fresnel(vec3 f0, float cos_theta) {
    return has_specular_layer(f0) ? fresnel_schlick(f0, cos_theta) : vec3(0.0);
}

// Schlick's F averaged over the cosine-weighted hemisphere, F0 + (1 - F0) 2 int (1 - mu)^5 mu dmu
// = F0 + (1 - F0) / 21: what the diffuse layer's weight 1 - F(n.v) leaves out on average; zero
// without a specular layer.
vec3 mean_fresnel(vec3 f0) {
    return has_specular_layer(f0) ? f0 + (1.0 - f0) / 21.0 : vec3(0.0);
}

// What the specular layer reflects of light arriving from every direction, seen from cos_view
// to the normal: its directional albedo A = F0 scale + bias, bilinear in the table of
// engine/core/specular_lobe.py over (cos_view, roughness) (Smith's masking makes it less than
// F(n.v) for rough lobes); none without a layer.
vec3 specular_layer_albedo(vec3 f0, float roughness, float cos_view) {
    if (!has_specular_layer(f0)) return vec3(0.0);
    vec2 x = clamp(vec2(cos_view, roughness), 0.0, 1.0) * float(SPECULAR_ALBEDO_SIZE - 1);
    ivec2 i = min(ivec2(x), ivec2(SPECULAR_ALBEDO_SIZE - 2));
    vec2 f = x - vec2(i);
    int row = i.y * SPECULAR_ALBEDO_SIZE + i.x;
    vec2 split = mix(mix(SPECULAR_ALBEDO[row], SPECULAR_ALBEDO[row + 1], f.x),
                     mix(SPECULAR_ALBEDO[row + SPECULAR_ALBEDO_SIZE], SPECULAR_ALBEDO[row + SPECULAR_ALBEDO_SIZE + 1], f.x), f.y);
    return f0 * split.x + split.y;
}

// The specular layer's directional albedo averaged over the cosine-weighted hemisphere (its
// hemispherical albedo), linear in roughness between the table's nodes; none without a layer.
vec3 specular_hemispherical_albedo(vec3 f0, float roughness) {
    if (!has_specular_layer(f0)) return vec3(0.0);
    float x = clamp(roughness, 0.0, 1.0) * float(SPECULAR_ALBEDO_SIZE - 1);
    int i = min(int(x), SPECULAR_ALBEDO_SIZE - 2);
    vec2 split = mix(SPECULAR_HEMISPHERICAL_ALBEDO[i], SPECULAR_HEMISPHERICAL_ALBEDO[i + 1], x - float(i));
    return f0 * split.x + split.y;
}

// The diffuse layer's albedo seen from a direction at cos_view to the normal: c_diff (1 - F(n.v)).
vec3 diffuse_layer_albedo(vec3 albedo, float metalness, float dielectric_f0, float cos_view) {
    return (1.0 - metalness) * albedo * (1.0 - layer_fresnel(specular_f0(albedo, metalness, dielectric_f0), cos_view));
}

// Hemispherical albedo of the layered model, what a voxel passes on as a Lambertian lobe:
// the diffuse layer's c_diff (1 - mean F) plus the specular layer's hemispherical albedo, so
// rho <= 1 for every k_d <= 1.
vec3 layered_albedo(vec3 albedo, float roughness, float metalness, float dielectric_f0) {
    vec3 f0 = specular_f0(albedo, metalness, dielectric_f0);
    return (1.0 - metalness) * albedo * (1.0 - mean_fresnel(f0)) + specular_hemispherical_albedo(f0, roughness);
}

// Smith's masking G1 of the Beckmann lobe of roughness alpha at cos_theta to the normal
// (Walter et al. 2007's rational fit, a = 1 / (alpha tan theta)).
float smith_g1(float cos_theta, float alpha) {
    float c = clamp(cos_theta, 1e-4, 1.0);
    float a = c / (alpha * sqrt(1.0 - c * c) + 1e-7);
    return a >= 1.6 ? 1.0 : (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
}

// f(l, v) of the layered model above (without the cosine).
vec3 brdf(vec3 n, vec3 l, vec3 v, vec3 albedo, float roughness, float metalness, float dielectric_f0) {
    vec3 f0 = specular_f0(albedo, metalness, dielectric_f0);
    if (!has_specular_layer(f0)) return (1.0 - metalness) * albedo / PI;  // F = 0: Lambert alone
    float cos_view = max(dot(n, v), 1e-4);
    vec3 diffuse = diffuse_layer_albedo(albedo, metalness, dielectric_f0, cos_view) / PI;
    vec3 h = normalize(l + v);
    float s = blinn_phong_exponent(roughness);
    float distribution = (s + 2.0) / (2.0 * PI) * pow(max(dot(n, h), 0.0), s);  // normalized Blinn-Phong D
    float alpha = pow(max(roughness, MIN_ROUGHNESS), 2.0);
    float cos_light = max(dot(n, l), 1e-4);
    float visibility = smith_g1(cos_light, alpha) * smith_g1(cos_view, alpha) / (4.0 * cos_light * cos_view);
    return diffuse + fresnel_schlick(f0, dot(v, h)) * distribution * visibility;
}
