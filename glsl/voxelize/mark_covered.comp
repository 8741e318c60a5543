#version 450 core
// Before a full voxelization over an existing grid: flag every covered voxel and list it as
// touched, so the resolve also empties the voxels that no surface covers any more.
#include "lib/voxel_slots.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    touch_voxel(unpack_voxel(covered[gl_GlobalInvocationID.x]));
}
