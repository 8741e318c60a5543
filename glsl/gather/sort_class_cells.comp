#version 450 core
// Sorts the covered cells of mip level 1 by the interleave class of the voxels in them
// (gather/sort_classes.comp marked them): a bucket per class for the cells of one class, then one
// for the cells where voxels of several classes meet (surfaces of several facings). When the
// progressive bounce composes one class, level 1 of the face views is built again over that
// class's bucket and the mixed one only. A counting sort, as gather/sort_classes.comp.
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_CELLS) readonly buffer Cells { uint cell_count[CELL_LIST_LEVELS]; uint cells[]; };
layout(std430, binding = SSBO_CELL_CLASS_BITS) readonly buffer CellClassBits { uint cell_class_bits[]; };
layout(std430, binding = SSBO_CLASS_BUCKETS) buffer ClassBuckets { uint buckets[]; };  // counts, then next free entries
layout(std430, binding = SSBO_CELLS_BY_CLASS) writeonly buffer CellsByClass { uint cells_by_class[]; };
uniform uint first;     // level 1's first entry in `cells`
uniform int interleave;
uniform bool scatter;

void main() {
    if (gl_GlobalInvocationID.x >= cell_count[1]) return;
    uint entry = cells[first + gl_GlobalInvocationID.x];
    uint classes = cell_class_bits[grid_index(unpack_voxel(entry), voxel_grid >> 1)];
    uint bucket = bitCount(classes) == 1 ? uint(findLSB(classes)) : uint(interleave);
    if (scatter) cells_by_class[atomicAdd(buckets[bucket], 1u)] = entry;
    else atomicAdd(buckets[bucket], 1u);
}
