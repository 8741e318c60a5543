#version 450 core
// Before a slab a scrolled clipmap level took in is voxelized: flag every voxel of the slab, a
// box of the level, and list it as touched, where drawing the slab's triangles once more would
// flag just the covered ones (the resolve leaves the others empty, as they are).
#include "lib/voxel_slots.glsl"

layout(local_size_x = LIST_GROUP) in;
uniform int marked_level;
uniform ivec3 box_min;   // the slab's first voxel, in the level's coordinates
uniform ivec3 box_size;  // its voxels along each axis

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(box_size.x * box_size.y * box_size.z)) return;
    ivec3 offset = ivec3(int(i) % box_size.x, (int(i) / box_size.x) % box_size.y, int(i) / (box_size.x * box_size.y));
    touch_voxel(level_voxel(box_min + offset, marked_level));
}
