#version 450 core
// Zeroes the face views at one mip level over a list of cells (the cells of the previous
// geometry, before their list is rebuilt), so cells no surface covers any more read empty.
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
layout(std430, binding = SSBO_CELLS) readonly buffer Cells { uint cell_count[CELL_LIST_LEVELS]; uint cells[]; };
uniform int level;
uniform uint first;

void main() {
    if (gl_GlobalInvocationID.x >= cell_count[level]) return;
    ivec3 cell = unpack_voxel(cells[first + gl_GlobalInvocationID.x]);
    for (int f = 0; f < VOXEL_FACES; ++f) imageStore(faces_out, face_texel(cell, f, voxel_grid >> level), vec4(0.0));
}
