#version 450 core
// The image over the G-buffer: direct light (with emission) plus cone-traced indirect light.
//   diffuse:  Lo = (1 - m) k_d sum_j w_j Lv(p, w_j, a_j), the lecture's 6 cones. They are
//             traced once per voxel whenever the voxel radiance changes (voxel_gather.comp);
//             a pixel interpolates the gathers of the voxels around p whose surfaces face its
//             way, and traces its own cones where none does (a thin surface seen from behind).
//   specular: Lo = F(w_o . n) Lv(p, w_s, a_s), w_s = 2 (w_o . n) n - w_o, traced per pixel
//   AO:       1 - sum_j w_j alpha_j within ao_distance, traced per pixel
#include "lib/gbuffer.glsl"
#include "lib/voxel_surface.glsl"
#include "lib/cone.glsl"
#include "lib/brdf.glsl"

#define OUTPUT_RADIANCE 0
#define OUTPUT_AO 1
layout(binding = TEX_DIRECT_LIGHT) uniform sampler2D direct_light;
layout(binding = TEX_VOXEL_GATHERED) uniform sampler3D voxel_gathered;
uniform vec3 camera_position;
uniform int output_kind;
uniform bool include_direct;
uniform bool include_diffuse;
uniform bool include_specular;
uniform float ao_distance;
layout(location = 0) out vec4 out_radiance;

// How much a voxel's gather stands for the gather at a surface with normal n: max(0, n . n_v)^8
// times the coherence |mean normal| (voxels of mixed surfaces count less).
#define FACING_EXPONENT 8.0

// The diffuse gather sum_j w_j Lv(p, w_j) at surface s from the gathers of the 8 voxels whose
// centres surround p, weighted trilinearly and by facing; false where no voxel faces n.
bool interpolated_gather(Surface s, out vec3 gathered) {
    vec3 c = voxel_uvw(s.position) * float(voxel_grid) - 0.5;
    ivec3 base = ivec3(floor(c));
    vec3 f = c - vec3(base);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < 8; ++k) {
        ivec3 corner = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ivec3 v = base + corner;
        if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(voxel_grid)))) continue;
        vec4 g = texelFetch(voxel_gathered, v, 0);
        if (g.a <= 0.0) continue;  // no surface, or none that reflects diffuse light
        vec3 n_v = texelFetch(voxel_normal, v, 0).xyz;
        vec3 trilinear = mix(1.0 - f, f, vec3(corner));
        float facing = pow(max(dot(s.normal, n_v) / max(length(n_v), 1e-6), 0.0), FACING_EXPONENT) * length(n_v);
        float weight = trilinear.x * trilinear.y * trilinear.z * facing;
        sum += weight * g.rgb;
        total += weight;
    }
    gathered = total > 1e-4 ? sum / total : vec3(0.0);
    return total > 1e-4;
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

void main() {
    Surface s = read_gbuffer(ivec2(gl_FragCoord.xy));
    if (!s.covered) { out_radiance = vec4(0.0); return; }
    if (output_kind == OUTPUT_AO) {
        float occlusion = trace_diffuse(s.position, s.normal, ao_distance).a;
        out_radiance = vec4(vec3(1.0 - clamp(occlusion, 0.0, 1.0)), 1.0);
        return;
    }
    vec3 radiance = include_direct ? texelFetch(direct_light, ivec2(gl_FragCoord.xy), 0).rgb : vec3(0.0);
    vec3 diffuse_albedo = (1.0 - s.metalness) * s.albedo;
    if (include_diffuse && any(greaterThan(diffuse_albedo, vec3(0.0)))) {
        vec3 gathered;
        if (!interpolated_gather(s, gathered)) gathered = trace_diffuse(s.position, s.normal, 1e9).rgb;
        radiance += diffuse_albedo * gathered;
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
