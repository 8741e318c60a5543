// The covered voxels (engine/voxels/grid.py: grid.covered): a voxel per record of the record
// pool (lib/voxel_records.glsl), packed by pack_voxel, NO_VOXEL at the records no voxel holds,
// up to `covered_count`, the records handed out so far (the resolve writes them:
// voxelize/resolve_sums.comp).
#include "lib/voxel.glsl"

layout(std430, binding = SSBO_COVERED) buffer CoveredVoxels { uint covered_count; uint covered[]; };

// The voxel that holds record k, where one does (false at a free record or past the count).
bool covered_voxel(uint k, out ivec3 v) {
    if (k >= covered_count || covered[k] == NO_VOXEL) return false;
    v = unpack_voxel(covered[k]);
    return true;
}
