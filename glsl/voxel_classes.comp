#version 450 core
// Sorts the covered voxels into `interleave` classes by their position in their 2x2x2 block,
// for the progressive bounce (one class gathers per frame, evenly spread over the surfaces),
// within a class by block of CLASS_BLOCK^3 voxels, and within a block by facing (the mean
// normal's dominant axis and sign), so neighbouring invocations of the gather trace
// neighbouring voxels with cones along the same directions, which end after as many steps.
// A counting sort: a pass counting the entries of each bucket (class, block, facing), then,
// once the host has turned the counts into each bucket's first entry, a pass scattering the
// voxels into their buckets.
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_COVERED) readonly buffer CoveredVoxels { uint covered_count; uint covered[]; };
layout(std430, binding = SSBO_CLASS_BUCKETS) buffer ClassBuckets { uint buckets[]; };  // counts, then next free entries
layout(std430, binding = SSBO_CLASS_LIST) writeonly buffer ClassList { uint class_list[]; };
uniform int interleave;
uniform bool scatter;

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    uint entry = covered[gl_GlobalInvocationID.x];
    ivec3 v = unpack_voxel(entry);
    int blocks = max(voxel_grid / CLASS_BLOCK, 1);
    ivec3 block = v / CLASS_BLOCK;
    int class_index = ((v.x & 1) | ((v.y & 1) << 1) | ((v.z & 1) << 2)) % interleave;
    vec3 n = texelFetch(voxel_normal, v, 0).xyz;
    int facing = dot(n, n) > 0.0 ? facing_face(n) : CLASS_FACINGS - 1;
    uint block_index = uint(class_index * blocks * blocks * blocks + block.x + blocks * (block.y + blocks * block.z));
    uint bucket = block_index * uint(CLASS_FACINGS) + uint(facing);
    if (scatter) class_list[atomicAdd(buckets[bucket], 1u)] = entry;
    else atomicAdd(buckets[bucket], 1u);
}
