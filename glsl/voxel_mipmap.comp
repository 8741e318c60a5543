#version 450 core
// One mip level of the face views, over its covered cells only: each cell is the mean of its
// 8 children one level finer (a box filter, as glGenerateMipmap), so a level-m cell holds the
// mean premultiplied radiance and coverage of the 2^m voxels along each side. Cells no surface
// covers are zero and stay zero (voxel_clear_cells.comp).
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = TEX_VOXEL_FACES) uniform sampler3D voxel_faces;
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
layout(std430, binding = SSBO_CELLS) readonly buffer Cells { uint cell_count[CELL_LIST_LEVELS]; uint cells[]; };
uniform int level;
uniform uint first;

void main() {
    if (gl_GlobalInvocationID.x >= cell_count[level]) return;
    ivec3 cell = unpack_voxel(cells[first + gl_GlobalInvocationID.x]);
    int side = voxel_grid >> level;
    for (int f = 0; f < VOXEL_FACES; ++f) {
        ivec3 child = face_texel(2 * cell, f, 2 * side);
        vec4 sum = vec4(0.0);
        for (int k = 0; k < 8; ++k) sum += texelFetch(voxel_faces, child + ivec3(k & 1, (k >> 1) & 1, k >> 2), level - 1);
        imageStore(faces_out, face_texel(cell, f, side), sum * 0.125);
    }
}
