// The cells a pass over a list segment (lib/list_segment.glsl) runs over, bound at CELLS: a
// mip level's cells, or voxels, whose cells at that level the pass takes (a cell once for each
// of its voxels listed).
#include "lib/voxel.glsl"
#include "lib/list_segment.glsl"

layout(std430, binding = SSBO_CELLS) readonly buffer Cells { uint cells[]; };
uniform bool voxel_entries;  // the list's entries are voxels, else cells of the level the pass runs at

// The cell at `level` that holds entry k of the segment (k < segment_count()).
ivec3 segment_cell(uint k, int level) {
    return unpack_voxel(cells[segment_first() + k]) >> (voxel_entries ? level : 0);
}

// The mip level of the grid that `image`, a mip level of a volume of the stacked levels, holds:
// its side is voxel_grid >> level.
int image_level(ivec3 image_size) {
    return findMSB(voxel_grid) - findMSB(image_size.x);
}
