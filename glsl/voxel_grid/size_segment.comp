#version 450 core
// A voxel list's segment row (row 0 of its table) from its count as the GPU left it (the list's
// first word, engine/voxels/lists.py VoxelList): its entries from word 1 on, and the group count
// of a dispatch over them, so that the passes over the list are dispatched indirectly and no
// count is read back. A count past the list's room (lib/list_append.glsl) is cut to the room.
#include "lib/list_segment.glsl"

layout(local_size_x = 1) in;
layout(std430, binding = SSBO_COUNTED) readonly buffer Counted { uint counted[]; };

void main() {
    uint count = min(counted[0], uint(counted.length()) - 1u);
    segments[0].dispatch = uvec4((count + uint(LIST_GROUP) - 1u) / uint(LIST_GROUP), 1u, 1u, 0u);
    segments[0].range = uvec4(1u, count, 0u, 0u);
}
