#version 450 core
// Before a full voxelization over an existing grid: flag every covered voxel of the slab and
// list it as touched, so the resolve also empties the voxels that no surface covers any more.
#include "lib/voxel_sums.glsl"
#include "lib/list_append.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_TOUCHED) buffer TouchedVoxels { uint touched_count; uint touched[]; };

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    uint entry = covered[gl_GlobalInvocationID.x];
    ivec3 v = unpack_voxel(entry);
    if (!in_slab(v)) return;
    uint i = sum_index(v);
    if ((atomicOr(voxel_sums[SUM_COUNT].value[i], TOUCHED_FLAG) & TOUCHED_FLAG) == 0u)
        APPEND(touched_count, touched, entry);
}
