// Per-voxel data of the covered voxels (engine/voxel_records.py): voxel v's record is
// voxel_records[voxel_index(v)] - 1 where a surface covers it (0 there: none), and each array
// of values holds an RGBA16F value per record, two halves to a uint.
#include "lib/voxel.glsl"

layout(std430, binding = SSBO_VOXEL_RECORD) buffer VoxelRecord { uint voxel_records[]; };

#define NO_RECORD 0xFFFFFFFFu

// The record of voxel v, or NO_RECORD where no surface covers it (or v lies outside the grid).
uint voxel_record(ivec3 v) {
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(voxel_grid)))) return NO_RECORD;
    return voxel_records[voxel_index(v)] - 1u;
}

vec4 unpack_value(uvec2 halves) {
    return vec4(unpackHalf2x16(halves.x), unpackHalf2x16(halves.y));
}

uvec2 pack_value(vec4 value) {
    return uvec2(packHalf2x16(value.xy), packHalf2x16(value.zw));
}
