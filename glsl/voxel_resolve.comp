#version 450 core
// Voxel resolve, over the list of covered voxels: divide the fixed-point sums by the fragment
// count into RGBA16F voxels, zero the sums for the next frame, and write the six one-sided
// face views of the radiance that cones read (rgb premultiplied by the face coverage in a).
// Radiance and albedo are premultiplied by opacity (a = 1 for a covered voxel, 0 for an empty
// one), so hardware mipmaps average empty children as transparent instead of darkening the
// colour. The normal keeps its length: |mean of unit normals| < 1 records how spread they are.
#include "engine_constants.glsl"
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_SUM_RADIANCE_R, r32ui) uniform uimage3D sum_radiance_r;
layout(binding = IMG_SUM_RADIANCE_G, r32ui) uniform uimage3D sum_radiance_g;
layout(binding = IMG_SUM_RADIANCE_B, r32ui) uniform uimage3D sum_radiance_b;
layout(binding = IMG_SUM_ALBEDO_R, r32ui) uniform uimage3D sum_albedo_r;
layout(binding = IMG_SUM_ALBEDO_G, r32ui) uniform uimage3D sum_albedo_g;
layout(binding = IMG_SUM_ALBEDO_B, r32ui) uniform uimage3D sum_albedo_b;
layout(binding = IMG_SUM_NORMAL_X, r32i) uniform iimage3D sum_normal_x;
layout(binding = IMG_SUM_NORMAL_Y, r32i) uniform iimage3D sum_normal_y;
layout(binding = IMG_SUM_NORMAL_Z, r32i) uniform iimage3D sum_normal_z;
layout(binding = IMG_SUM_COUNT, r32ui) uniform uimage3D sum_count;
layout(binding = IMG_OUT_RADIANCE, rgba16f) uniform writeonly image3D out_radiance;
layout(binding = IMG_OUT_NORMAL, rgba16f) uniform writeonly image3D out_normal;
layout(binding = IMG_OUT_ALBEDO, rgba16f) uniform writeonly image3D out_albedo;
layout(binding = IMG_OUT_DIRECTIONAL, rgba16f) uniform writeonly image3D out_directional[VOXEL_FACES];
layout(std430, binding = SSBO_OCCUPIED) readonly buffer OccupiedVoxels { uint occupied_count; uint occupied[]; };

void main() {
    if (gl_GlobalInvocationID.x >= occupied_count) return;
    ivec3 v = unpack_voxel(occupied[gl_GlobalInvocationID.x]);
    uint count = imageLoad(sum_count, v).r;
    float samples = float(min(count, uint(VOXEL_MAX_FRAGMENTS)));
    float to_value = 1.0 / (samples * VOXEL_FIXED_SCALE);
    vec3 radiance = vec3(imageLoad(sum_radiance_r, v).r, imageLoad(sum_radiance_g, v).r, imageLoad(sum_radiance_b, v).r) * to_value;
    vec3 albedo = vec3(imageLoad(sum_albedo_r, v).r, imageLoad(sum_albedo_g, v).r, imageLoad(sum_albedo_b, v).r) * to_value;
    vec3 normal = vec3(imageLoad(sum_normal_x, v).r, imageLoad(sum_normal_y, v).r, imageLoad(sum_normal_z, v).r) / (samples * VOXEL_NORMAL_SCALE);
    imageStore(out_radiance, v, vec4(radiance, 1.0));
    imageStore(out_normal, v, vec4(normal, 1.0));
    imageStore(out_albedo, v, vec4(albedo, 1.0));
    for (int f = 0; f < VOXEL_FACES; ++f) {
        float coverage = face_coverage(normal, f);
        imageStore(out_directional[f], v, vec4(radiance * coverage, coverage));
    }
    imageStore(sum_count, v, uvec4(0u));
    imageStore(sum_radiance_r, v, uvec4(0u));
    imageStore(sum_radiance_g, v, uvec4(0u));
    imageStore(sum_radiance_b, v, uvec4(0u));
    imageStore(sum_albedo_r, v, uvec4(0u));
    imageStore(sum_albedo_g, v, uvec4(0u));
    imageStore(sum_albedo_b, v, uvec4(0u));
    imageStore(sum_normal_x, v, ivec4(0));
    imageStore(sum_normal_y, v, ivec4(0));
    imageStore(sum_normal_z, v, ivec4(0));
}
