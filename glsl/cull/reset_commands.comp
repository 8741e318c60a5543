#version 450 core
// A draw list's commands before its views are culled: each draws its cluster's indices with no
// instance yet, its instances' slots from its first for `view_count` views (the command table's
// row: index count, first index, base vertex, first slot per view).
#include "engine_constants.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_COMMAND_TABLE) readonly buffer CommandTable { uvec4 command_table[]; };
layout(std430, binding = SSBO_DRAW_COMMANDS) writeonly buffer DrawCommands { uint commands[]; };  // 5 per command
uniform uint view_count;

void main() {
    uint command = gl_GlobalInvocationID.x;
    if (command >= uint(command_table.length())) return;
    uvec4 row = command_table[command];
    commands[5u * command] = row.x;
    commands[5u * command + 1u] = 0u;
    commands[5u * command + 2u] = row.y;
    commands[5u * command + 3u] = row.z;
    commands[5u * command + 4u] = row.w * view_count;
}
