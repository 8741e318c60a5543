#version 450 core
// Cone-traced global illumination over the G-buffer:
//   diffuse:  Lo = (1 - m) k_d sum_j w_j Lv(p, w_j, a_j)       (6 cones, the lecture's table)
//   specular: Lo = F(w_o . n) Lv(p, w_s, a_s), w_s = 2 (w_o . n) n - w_o
//   AO:       1 - sum_j w_j alpha_j within ao_distance
// composited with the direct light (which includes emission) according to the mode. The
// diffuse/AO sums come from cone_gather.frag at half resolution, upsampled here.
#include "lib/gbuffer.glsl"
#include "lib/cone.glsl"
#include "lib/brdf.glsl"

#define OUTPUT_RADIANCE 0
#define OUTPUT_AO 1
layout(binding = TEX_DIRECT_LIGHT) uniform sampler2D direct_light;
layout(binding = TEX_DIFFUSE_GATHER) uniform sampler2D diffuse_gather;
uniform vec3 camera_position;
uniform int output_kind;
uniform bool include_direct;
uniform bool include_diffuse;
uniform bool include_specular;
uniform float gather_distance;  // the AO distance in AO mode, else everywhere
layout(location = 0) out vec4 out_radiance;

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

// Edge-aware upsampling of the half-resolution gather: the four nearest samples (sample q was
// traced at pixel 2q), weighted bilinearly and by how well their surface matches this pixel's
// (same facing, same plane). Where none matches, at silhouettes and thin parts, the pixel
// traces its own cones.
vec4 upsampled_gather(ivec2 pixel, Surface s, float gather_distance) {
    vec2 h = vec2(pixel) / 2.0;
    ivec2 base = ivec2(floor(h));
    vec2 f = h - vec2(base);
    ivec2 last = textureSize(diffuse_gather, 0) - 1;
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 corner = ivec2(k & 1, k >> 1);
        ivec2 q = min(base + corner, last);
        Surface t = read_gbuffer(min(2 * q, textureSize(gbuffer_position, 0) - 1));
        if (!t.covered) continue;
        vec2 bilinear2 = mix(1.0 - f, f, vec2(corner));
        float facing = pow(max(dot(s.normal, t.normal), 0.0), 32.0);
        float plane = exp(-abs(dot(s.normal, t.position - s.position)) / voxel_size);
        float weight = max(bilinear2.x * bilinear2.y, 1e-3) * facing * plane;
        sum += weight * texelFetch(diffuse_gather, q, 0);
        total += weight;
    }
    return total > 1e-3 ? sum / total : trace_diffuse(s.position, s.normal, gather_distance);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    Surface s = read_gbuffer(pixel);
    if (!s.covered) { out_radiance = vec4(0.0); return; }
    if (output_kind == OUTPUT_AO) {
        float occlusion = upsampled_gather(pixel, s, gather_distance).a;
        out_radiance = vec4(vec3(1.0 - clamp(occlusion, 0.0, 1.0)), 1.0);
        return;
    }
    vec3 radiance = include_direct ? texelFetch(direct_light, pixel, 0).rgb : vec3(0.0);
    if (include_diffuse && s.metalness < 1.0) {
        vec3 gathered = upsampled_gather(pixel, s, gather_distance).rgb;
        radiance += (1.0 - s.metalness) * s.albedo * gathered;
    }
    vec3 f0 = specular_f0(s.albedo, s.metalness, s.dielectric_f0);
    if (include_specular && any(greaterThan(f0, vec3(0.0)))) {
        vec3 wo = normalize(camera_position - s.position);
        float cos_o = max(dot(wo, s.normal), 0.0);
        vec3 ws = 2.0 * cos_o * s.normal - wo;
        vec4 cone = trace_cone(s.position, s.normal, ws, specular_tan_half_angle(s.roughness), 1e9);
        radiance += fresnel_schlick(f0, cos_o) * cone.rgb;
    }
    out_radiance = vec4(radiance, 1.0);
}
