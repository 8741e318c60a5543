#version 450 core
// Voxelization, fragment stage: one fragment = one surface sample in one voxel. Its outgoing
// diffuse radiance (emission + direct light, with the G-buffer pass's shadow maps), normal and
// albedo are added to fixed-point sums with image atomics, together with a fragment count, so
// the average is order-independent and the grid is identical from frame to frame. The first
// fragment in a voxel appends it to the list of covered voxels the later passes work through.
#include "lib/voxel.glsl"
#include "lib/lights.glsl"

in vec3 gs_position;
in vec3 gs_normal;
flat in vec4 gs_pixel_bounds;
flat in vec3 gs_face_normal;
uniform vec3 albedo;
uniform float metalness;
uniform vec3 emission;

layout(binding = IMG_SUM_RADIANCE_R, r32ui) uniform coherent uimage3D sum_radiance_r;
layout(binding = IMG_SUM_RADIANCE_G, r32ui) uniform coherent uimage3D sum_radiance_g;
layout(binding = IMG_SUM_RADIANCE_B, r32ui) uniform coherent uimage3D sum_radiance_b;
layout(binding = IMG_SUM_ALBEDO_R, r32ui) uniform coherent uimage3D sum_albedo_r;
layout(binding = IMG_SUM_ALBEDO_G, r32ui) uniform coherent uimage3D sum_albedo_g;
layout(binding = IMG_SUM_ALBEDO_B, r32ui) uniform coherent uimage3D sum_albedo_b;
layout(binding = IMG_SUM_NORMAL_X, r32i) uniform coherent iimage3D sum_normal_x;
layout(binding = IMG_SUM_NORMAL_Y, r32i) uniform coherent iimage3D sum_normal_y;
layout(binding = IMG_SUM_NORMAL_Z, r32i) uniform coherent iimage3D sum_normal_z;
layout(binding = IMG_SUM_COUNT, r32ui) uniform coherent uimage3D sum_count;
layout(std430, binding = SSBO_OCCUPIED) buffer OccupiedVoxels { uint occupied_count; uint occupied[]; };

uint fixed_point(float x) {
    return uint(clamp(x, 0.0, VOXEL_MAX_VALUE) * VOXEL_FIXED_SCALE + 0.5);
}

int fixed_point_signed(float x) {
    return int(round(clamp(x, -1.0, 1.0) * VOXEL_NORMAL_SCALE));
}

void main() {
    // Dilation grows the triangle at acute corners; clip it to its own bounding box.
    vec2 pixel = gl_FragCoord.xy;
    if (any(lessThan(pixel, gs_pixel_bounds.xy)) || any(greaterThan(pixel, gs_pixel_bounds.zw))) discard;
    ivec3 voxel = ivec3(floor(voxel_uvw(gs_position) * float(voxel_grid)));
    if (any(lessThan(voxel, ivec3(0))) || any(greaterThanEqual(voxel, ivec3(voxel_grid)))) discard;

    vec3 n = normalize(gs_normal);
    // Diffuse outgoing radiance: Lo = Le + (1 - m) k_d / pi * sum_lights E_l.
    vec3 diffuse_albedo = (1.0 - metalness) * albedo;
    vec3 irradiance = vec3(0.0);
    for (int i = 0; i < light_count; ++i) {
        vec3 l;
        irradiance += light_irradiance(i, gs_position, n, l);
    }
    vec3 radiance = emission + diffuse_albedo / PI * irradiance;

    uint earlier_fragments = imageAtomicAdd(sum_count, voxel, 1u);
    if (earlier_fragments == 0u) occupied[atomicAdd(occupied_count, 1u)] = pack_voxel(voxel);  // first in this voxel
    if (earlier_fragments >= uint(VOXEL_MAX_FRAGMENTS)) return;  // headroom of the sums
    imageAtomicAdd(sum_radiance_r, voxel, fixed_point(radiance.r));
    imageAtomicAdd(sum_radiance_g, voxel, fixed_point(radiance.g));
    imageAtomicAdd(sum_radiance_b, voxel, fixed_point(radiance.b));
    imageAtomicAdd(sum_albedo_r, voxel, fixed_point(diffuse_albedo.r));
    imageAtomicAdd(sum_albedo_g, voxel, fixed_point(diffuse_albedo.g));
    imageAtomicAdd(sum_albedo_b, voxel, fixed_point(diffuse_albedo.b));
    imageAtomicAdd(sum_normal_x, voxel, fixed_point_signed(n.x));
    imageAtomicAdd(sum_normal_y, voxel, fixed_point_signed(n.y));
    imageAtomicAdd(sum_normal_z, voxel, fixed_point_signed(n.z));
}
