// The scene's draws (engine/scene_gpu.py), and the values of a draw list's instances
// (engine/passes/cull.py): every command of a list draws one mesh's cluster, once per
// instance, and an instance's value (a vertex shader's in_instance: an attribute that steps
// once an instance, offset by the command's base instance) holds the index of its draw
// (DRAW_INDEX_MASK) and of its view (DRAW_VIEW_SHIFT). Where HELD_DRAWS is defined, a value
// with DRAW_HELD set stands for a draw as the voxels hold it (its index in held_draws): the
// voxelizer marks what a moved draw covered.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_DRAWS) readonly buffer Draws { DrawRecord draws[]; };
#ifdef HELD_DRAWS
layout(std430, binding = SSBO_HELD_DRAWS) readonly buffer HeldDraws { DrawRecord held_draws[]; };
#endif

bool value_held(uint value) {
    return (value & DRAW_HELD) != 0u;
}

DrawRecord value_draw(uint value) {
#ifdef HELD_DRAWS
    if (value_held(value)) return held_draws[value & DRAW_INDEX_MASK];
#endif
    return draws[value & DRAW_INDEX_MASK];
}

uint value_view(uint value) {
    return (value >> DRAW_VIEW_SHIFT) & DRAW_VIEW_MASK;
}
