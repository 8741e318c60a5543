#version 450 core
// A segment row from a list's count as the GPU left it (counted[count_index]): its entries
// from entries_first on, and the group count of a dispatch over them, so that the passes over
// the list are dispatched indirectly and no count is read back. A count past the list's room
// (lib/list_append.glsl) is cut to the room.
#include "lib/list_segment.glsl"

layout(local_size_x = 1) in;
layout(std430, binding = SSBO_COUNTED) readonly buffer Counted { uint counted[]; };
uniform uint count_index;
uniform uint entries_first;
uniform uint row;

void main() {
    uint count = min(counted[count_index], uint(counted.length()) - entries_first);
    segments[row].dispatch = uvec4((count + uint(LIST_GROUP) - 1u) / uint(LIST_GROUP), 1u, 1u, 0u);
    segments[row].range = uvec4(entries_first, count, 0u, 0u);
}
