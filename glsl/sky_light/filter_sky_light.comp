#version 450 core
// The sky's light the image and the light injection read: at each covered voxel the mean of
// what the cones brought (sky_light/trace_sky_cones.comp at the anchors, gather/interpolate_from_anchors.comp between them)
// over the voxels within SKY_FILTER_RADIUS whose surfaces face alike,
//   E(v) = sum_u W(v, u) E_traced(u) / sum_u W(v, u),
//   W = prod_k (1 - |u_k - v_k| / (R + 1)) facing_weight(n_v, n_u),
// which puts the cone sets of the anchors around v, each offset by its own jitter, together
// into one estimate: no bands where a cone of one shared set crosses an opening's edge.
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = TEX_VOXEL_TRACED_SKY_IRRADIANCE) uniform sampler3D sky_traced;  // a = 1 where traced or interpolated
layout(binding = IMG_SKY_IRRADIANCE_OUT, rgba16f) uniform writeonly image3D sky_irradiance_out;
#include "lib/covered_voxels.glsl"

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    ivec3 v = unpack_voxel(covered[gl_GlobalInvocationID.x]);
    vec3 n_v = texelFetch(voxel_normal, v, 0).xyz;
    vec3 sum = vec3(0.0);
    float total = 0.0;
    if (dot(n_v, n_v) > 0.0) {
        vec3 n = normalize(n_v);
        const float reach = float(SKY_FILTER_RADIUS + 1);
        for (int dz = -SKY_FILTER_RADIUS; dz <= SKY_FILTER_RADIUS; ++dz)
        for (int dy = -SKY_FILTER_RADIUS; dy <= SKY_FILTER_RADIUS; ++dy)
        for (int dx = -SKY_FILTER_RADIUS; dx <= SKY_FILTER_RADIUS; ++dx) {
            ivec3 u = v + ivec3(dx, dy, dz);
            if (any(lessThan(u, ivec3(0))) || any(greaterThanEqual(u, ivec3(voxel_grid)))) continue;
            vec4 traced = texelFetch(sky_traced, u, 0);
            if (traced.a <= 0.0) continue;  // not lit by the sky: no surface, or one that reflects nothing
            vec3 n_u = texelFetch(voxel_normal, u, 0).xyz;
            if (dot(n_u, n_u) <= 0.0) continue;
            vec3 tent = 1.0 - abs(vec3(dx, dy, dz)) / reach;
            float weight = tent.x * tent.y * tent.z * facing_weight(n, n_u);
            sum += weight * traced.rgb;
            total += weight;
        }
    }
    imageStore(sky_irradiance_out, v, vec4(total > 0.0 ? sum / total : vec3(0.0), total > 0.0 ? 1.0 : 0.0));
}
