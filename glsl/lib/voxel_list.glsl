// The voxels a pass runs over (engine/voxel_grid.py: a VoxelSegment of a list), each packed by
// pack_voxel: entries first .. first + count - 1 of voxel_list.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_VOXEL_LIST) readonly buffer VoxelList { uint voxel_list[]; };
uniform uint first;  // the segment of the list the pass runs over
uniform uint count;
