#version 450 core
// Sorts the covered voxels into `interleave` classes by their position in their 2x2x2 block,
// for the progressive bounce (one class gathers per frame, evenly spread over the surfaces):
// a counting pass, then a scatter pass into each class's segment of the class list.
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_COVERED) readonly buffer CoveredVoxels { uint covered_count; uint covered[]; };
layout(std430, binding = SSBO_CLASS_COUNTS) buffer ClassCounts { uint class_count[MAX_INTERLEAVE]; uint class_fill[MAX_INTERLEAVE]; };
layout(std430, binding = SSBO_CLASS_LIST) writeonly buffer ClassList { uint class_list[]; };
uniform int interleave;
uniform bool scatter;
uniform uint class_first[MAX_INTERLEAVE];

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    uint entry = covered[gl_GlobalInvocationID.x];
    ivec3 v = unpack_voxel(entry);
    int c = ((v.x & 1) | ((v.y & 1) << 1) | ((v.z & 1) << 2)) % interleave;
    if (scatter) class_list[class_first[c] + atomicAdd(class_fill[c], 1u)] = entry;
    else atomicAdd(class_count[c], 1u);
}
