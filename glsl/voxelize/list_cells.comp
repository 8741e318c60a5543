#version 450 core
// The covered cells of mip level `level`: the parents of the covered cells one level finer
// (the covered voxels for level 1), each listed once (a stamp per cell and rebuild).
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_CELLS) buffer Cells { uint cell_count[CELL_LIST_LEVELS]; uint cells[]; };
layout(std430, binding = SSBO_CELL_STAMPS) buffer CellStamps { uint stamps[]; };
uniform int level;
uniform uint source_first;  // first entry of level - 1 in `cells` (unused for level 1)
uniform uint target_first;  // first entry of this level in `cells`
uniform uint stamp_first;   // first stamp of this level
uniform uint generation;    // this rebuild's stamp

void main() {
    uint k = gl_GlobalInvocationID.x;
    uint count = level == 1 ? covered_count : cell_count[level - 1];
    if (k >= count) return;
    uint entry = level == 1 ? covered[k] : cells[source_first + k];
    if (entry == NO_VOXEL) return;  // a free record
    ivec3 cell = unpack_voxel(entry) >> 1;
    int side = voxel_grid >> level;
    uint stamp = stamp_first + grid_index(cell, side);
    if (atomicExchange(stamps[stamp], generation) != generation)
        cells[target_first + atomicAdd(cell_count[level], 1u)] = pack_voxel(cell);
}
