#version 450 core
// Before a full voxelization over an existing grid: flag every covered voxel and list it as
// touched, so the resolve also empties the voxels that no surface covers any more.
#include "lib/voxel.glsl"
#include "lib/voxel_sums.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_TOUCHED) buffer TouchedVoxels { uint touched_count; uint touched[]; };

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    uint entry = covered[gl_GlobalInvocationID.x];
    uint i = voxel_index(unpack_voxel(entry));
    if ((atomicOr(voxel_sums[SUM_COUNT].value[i], TOUCHED_FLAG) & TOUCHED_FLAG) == 0u)
        touched[atomicAdd(touched_count, 1u)] = entry;
}
