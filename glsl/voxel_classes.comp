#version 450 core
// Sorts the covered voxels for the bounce: first the anchors, which trace the gather
// (lib/gather_anchors.glsl), then the others, which take it from them. Each part in
// `interleave` classes for the progressive bounce (one class gathers per frame, evenly spread
// over the surfaces): an anchor by its place among the anchors around it, another voxel by its
// position in its 2x2x2 block. Within a class by block of CLASS_BLOCK^3 voxels, and within a
// block by facing (the mean normal's dominant axis and sign), so neighbouring invocations of
// the gather trace neighbouring voxels with cones along the same directions, which end after
// as many steps. A counting sort: a pass counting the entries of each bucket (part, class,
// block, facing), then, once the host has turned the counts into each bucket's first entry, a
// pass scattering the voxels into their buckets. voxel_anchors.comp has found the anchors.
#include "lib/gather_anchors.glsl"

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
    vec3 n = texelFetch(voxel_normal, v, 0).xyz;
    bool anchor = gather_anchors[voxel_index(v)] == ANCHOR_SELF;
    int class_index = anchor ? anchor_class(v, n, interleave) : ((v.x & 1) | ((v.y & 1) << 1) | ((v.z & 1) << 2)) % interleave;
    int part = anchor ? 0 : 1;
    int facing = dot(n, n) > 0.0 ? facing_face(n) : CLASS_FACINGS - 1;
    uint block_index = uint((part * interleave + class_index) * blocks * blocks * blocks + block.x + blocks * (block.y + blocks * block.z));
    uint bucket = block_index * uint(CLASS_FACINGS) + uint(facing);
    if (scatter) class_list[atomicAdd(buckets[bucket], 1u)] = entry;
    else atomicAdd(buckets[bucket], 1u);
}
