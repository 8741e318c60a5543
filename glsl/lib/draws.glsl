// The scene's draws (engine/gpu/scene_buffers.py), and the values of a draw list's instances
// (engine/passes/cull.py): every command of a list draws one mesh's cluster, once per
// instance, and an instance's value (a vertex shader's in_instance: an attribute that steps
// once an instance, offset by the command's base instance) holds the index of its draw
// (DRAW_INDEX_MASK) and of its view (DRAW_VIEW_SHIFT). Where HELD_DRAWS is defined, a value
// with DRAW_HELD set stands for a draw as the voxels hold it (its index in held_draws): the
// voxelizer marks what a moved draw covered.
#include "engine_constants.glsl"
#include "lib/normal_transform.glsl"

layout(std430, binding = SSBO_DRAWS) readonly buffer Draws { DrawRecord draws[]; };
#ifdef HELD_DRAWS
layout(std430, binding = SSBO_HELD_DRAWS) readonly buffer HeldDraws { DrawRecord held_draws[]; };
#endif

bool value_held(uint value) {
    return (value & DRAW_HELD) != 0u;
}

// The world matrix of a value's draw without its last row (0, 0, 0, 1): its columns' xyz
// only, since on llvmpipe every component a vertex shader loads from a buffer costs.
mat4x3 value_world(uint value) {
    uint index = value & DRAW_INDEX_MASK;
#ifdef HELD_DRAWS
    if (value_held(value)) {
        return mat4x3(held_draws[index].world[0].xyz, held_draws[index].world[1].xyz,
                      held_draws[index].world[2].xyz, held_draws[index].world[3].xyz);
    }
#endif
    return mat4x3(draws[index].world[0].xyz, draws[index].world[1].xyz, draws[index].world[2].xyz,
                  draws[index].world[3].xyz);
}

// The material of a value's draw.
uint value_material(uint value) {
#ifdef HELD_DRAWS
    if (value_held(value)) return held_draws[value & DRAW_INDEX_MASK].info.x;
#endif
    return draws[value & DRAW_INDEX_MASK].info.x;
}


// Whether a value's draw is posed (its own copy of its mesh in the pool: engine/passes/pose.py).
bool value_posed(uint value) {
    return draws[value & DRAW_INDEX_MASK].info.y != 0u;
}

uint value_view(uint value) {
    return (value >> DRAW_VIEW_SHIFT) & DRAW_VIEW_MASK;
}
