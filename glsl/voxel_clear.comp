#version 450 core
// Clears the voxels that were covered last frame and are empty now (no fragment this frame),
// in every volume, both face sets and the bounce pass's cache. Together with zero-initialized volumes this keeps every
// empty voxel zero without touching the whole grid each frame.
#include "engine_constants.glsl"
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_SUM_COUNT, r32ui) uniform readonly uimage3D sum_count;
layout(binding = IMG_OUT_RADIANCE, rgba16f) uniform writeonly image3D out_radiance;
layout(binding = IMG_OUT_NORMAL, rgba16f) uniform writeonly image3D out_normal;
layout(binding = IMG_OUT_ALBEDO, rgba16f) uniform writeonly image3D out_albedo;
layout(binding = IMG_OUT_DIRECTIONAL, rgba16f) uniform writeonly image3D out_directional[VOXEL_FACES];
layout(binding = IMG_OTHER_DIRECTIONAL, rgba16f) uniform writeonly image3D other_directional[VOXEL_FACES];
layout(binding = IMG_GATHERED, rgba16f) uniform writeonly image3D gathered;
layout(std430, binding = SSBO_PREVIOUS_OCCUPIED) readonly buffer PreviousVoxels { uint previous_count; uint previous[]; };

void main() {
    if (gl_GlobalInvocationID.x >= previous_count) return;
    ivec3 v = unpack_voxel(previous[gl_GlobalInvocationID.x]);
    if (imageLoad(sum_count, v).r != 0u) return;  // still covered: the resolve rewrites it
    imageStore(out_radiance, v, vec4(0.0));
    imageStore(out_normal, v, vec4(0.0));
    imageStore(out_albedo, v, vec4(0.0));
    imageStore(gathered, v, vec4(0.0));
    for (int f = 0; f < VOXEL_FACES; ++f) {
        imageStore(out_directional[f], v, vec4(0.0));
        imageStore(other_directional[f], v, vec4(0.0));
    }
}
