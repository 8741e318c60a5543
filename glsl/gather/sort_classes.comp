#version 450 core
// Sorts the covered voxels into `interleave` classes for the progressive bounce (one class is
// updated per frame, evenly spread over the surfaces: voxel_class). Each class is one run of
// the list, its anchors (which trace the gather: lib/gather_anchors.glsl) first (part 0), then
// the voxels that interpolate them (part 1), then those beneath a finer level, which take the
// finer voxels' (part 2), so that a pass over a whole class (injection, composition) is one
// segment. Within a part level by level (the levels' blocks follow along z: a part's voxels of
// one level are one run), by block of CLASS_BLOCK^3 voxels, and within a block by facing (the
// mean normal's dominant axis and sign), so neighbouring invocations of the gather trace
// neighbouring voxels with cones along the same directions, which end after as many steps.
// A counting sort: a pass counting the entries of each bucket
// (class, part, block, facing), then, once the host has turned the counts into each bucket's first entry, a
// pass scattering the voxels into their buckets, which also marks the classes each level-1
// cell holds (CELL_CLASS_BITS, zeroed by the host before). gather/find_anchors.comp has found the
// anchors.
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_CLASS_BUCKETS) buffer ClassBuckets { uint buckets[]; };  // counts, then next free entries
layout(std430, binding = SSBO_CLASS_LIST) writeonly buffer ClassList { uint class_list[]; };
layout(std430, binding = SSBO_CELL_CLASS_BITS) buffer CellClassBits { uint cell_class_bits[]; };  // per level-1 cell: a bit per class
uniform int interleave;
uniform bool scatter;

void main() {
    uint record = gl_GlobalInvocationID.x;
    ivec3 v;
    if (!covered_voxel(record, v)) return;
    int blocks = max(voxel_grid / CLASS_BLOCK, 1);  // per side of a level; the levels' blocks follow along z
    ivec3 block = v / CLASS_BLOCK;
    uint anchors = gather_anchors[record];
    bool anchor = (anchors & ANCHOR_SELF) != 0u;
    int facing = int(anchors >> ANCHOR_FACING_SHIFT);
    int class_index = voxel_class(v, facing, interleave);
    int part = anchor ? 0 : (anchors & ANCHOR_FINER) != 0u ? 2 : 1;
    uint block_index = uint((class_index * CLASS_PARTS + part) * voxel_levels * blocks * blocks * blocks + block.x
                            + blocks * (block.y + blocks * block.z));
    uint bucket = block_index * uint(CLASS_FACINGS) + uint(facing);
    if (scatter) {
        class_list[atomicAdd(buckets[bucket], 1u)] = pack_voxel(v);
        atomicOr(cell_class_bits[grid_index(v >> 1, voxel_grid >> 1)], 1u << class_index);
    } else {
        atomicAdd(buckets[bucket], 1u);
    }
}
