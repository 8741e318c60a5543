#version 450 core
// The segment rows of the covered cells of mip levels 1..top_level from their counts as the GPU
// left them (voxelize/list_cells.comp): row k holds level k's entries and the group count of a
// dispatch over them. A count past the level's room is cut to it.
#include "lib/list_segment.glsl"

layout(local_size_x = CELL_LIST_LEVELS) in;
layout(std430, binding = SSBO_COUNTED) readonly buffer Counted { uint counted[]; };  // the cells: a count per level, then the entries
uniform int top_level;
uniform uint level_first[CELL_LIST_LEVELS];  // per level its first entry after the counts

void main() {
    int level = int(gl_LocalInvocationID.x);
    if (level < 1 || level > top_level) return;
    uint first = uint(CELL_LIST_LEVELS) + level_first[level];
    uint room = (level < top_level ? uint(CELL_LIST_LEVELS) + level_first[level + 1] : uint(counted.length())) - first;
    uint count = min(counted[level], room);
    segments[level].dispatch = uvec4((count + uint(LIST_GROUP) - 1u) / uint(LIST_GROUP), 1u, 1u, 0u);
    segments[level].range = uvec4(first, count, 0u, 0u);
}
