#version 450 core
// The covered cells of every mip level 1..top_level, in one pass over the covered voxels: each
// voxel's cell at level 1, then its parent, and so on, each listed once a rebuild (a stamp per
// cell). The voxel that stamps a cell first lists it and goes on to its parent; one that finds
// a cell stamped stops there: that cell's parents are listed by the voxel that stamped it.
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_CELLS) buffer Cells { uint cell_count[CELL_LIST_LEVELS]; uint cells[]; };
layout(std430, binding = SSBO_CELL_STAMPS) buffer CellStamps { uint stamps[]; };
uniform int top_level;                        // the coarsest mip level listed (log2 n)
uniform uint level_first[CELL_LIST_LEVELS];   // per level its first entry in `cells` and its first stamp
uniform uint generation;                      // this rebuild's stamp

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= covered_count) return;
    uint entry = covered[k];
    if (entry == NO_VOXEL) return;  // a free record
    ivec3 cell = unpack_voxel(entry);
    for (int level = 1; level <= top_level; ++level) {
        cell >>= 1;
        uint stamp = level_first[level] + grid_index(cell, voxel_grid >> level);
        if (atomicExchange(stamps[stamp], generation) == generation) return;  // listed, and its parents with it
        cells[level_first[level] + atomicAdd(cell_count[level], 1u)] = pack_voxel(cell);
    }
}
