// The voxels a pass runs over (engine/voxel_lists.py: a VoxelSegment of a list), each packed by
// pack_voxel: the segment of voxel_list that lib/list_segment.glsl gives.
#include "lib/list_segment.glsl"

layout(std430, binding = SSBO_VOXEL_LIST) readonly buffer VoxelList { uint voxel_list[]; };
