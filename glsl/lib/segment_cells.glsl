// The cells a pass over a list segment (lib/list_segment.glsl) runs over, bound at CELLS: a
// mip level's cells, or voxels, whose cells at that level the pass takes (a cell once for each
// of its voxels listed).
#include "lib/voxel.glsl"
#include "lib/list_segment.glsl"

layout(std430, binding = SSBO_CELLS) readonly buffer Cells { uint cells[]; };
uniform int entry_level;  // the level of the list's entries: that of the cells, or 0 for voxels

// The cell at `level` that holds entry k of the segment (k < segment_count()).
ivec3 segment_cell(uint k, int level) {
    return unpack_voxel(cells[segment_first() + k]) >> (level - entry_level);
}
