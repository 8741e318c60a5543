#version 450 core
// Before the levels marked_levels holds (bit k: level k) are voxelized anew, over an existing
// grid: flag every covered voxel of them and list it as touched, so the resolve also empties
// the voxels that no surface covers any more.
#include "lib/voxel_slots.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"

uniform uint marked_levels;

void main() {
    ivec3 v;
    if (covered_voxel(gl_GlobalInvocationID.x, v) && in_level_mask(marked_levels, v)) touch_voxel(v);
}
