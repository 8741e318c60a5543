#version 450 core
// Before a full voxelization over an existing grid: flag every covered voxel and list it as
// touched, so the resolve also empties the voxels that no surface covers any more.
#include "lib/voxel_slots.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"

void main() {
    ivec3 v;
    if (covered_voxel(gl_GlobalInvocationID.x, v)) touch_voxel(v);
}
