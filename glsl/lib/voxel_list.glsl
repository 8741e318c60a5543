// The voxels a pass runs over (engine/voxels/lists.py: a VoxelSegment of a list), each packed by
// pack_voxel: the segment of voxel_list that lib/list_segment.glsl gives.
#include "lib/voxel.glsl"
#include "lib/list_segment.glsl"

layout(std430, binding = SSBO_VOXEL_LIST) readonly buffer VoxelList { uint voxel_list[]; };

// Entry `index` of the segment as voxel v: false past the segment's end, and at the entry of a
// record no voxel holds (NO_VOXEL, in the covered list).
bool segment_voxel(uint index, out ivec3 v) {
    if (index >= segment_count()) return false;
    uint entry = voxel_list[segment_first() + index];
    v = unpack_voxel(entry);
    return entry != NO_VOXEL;
}
