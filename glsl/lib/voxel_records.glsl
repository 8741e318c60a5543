// Per-voxel data of the covered voxels (engine/voxels/records.py): voxel v's record is
// voxel_records[voxel_index(v)] - 1 where a surface covers it (0 there: none), and each array
// of values holds an RGBA16F value per record, two halves to a uint.
#include "lib/voxel.glsl"

layout(std430, binding = SSBO_VOXEL_RECORD) buffer VoxelRecord { uint voxel_records[]; };

#define NO_RECORD 0xFFFFFFFFu

// The record of voxel v, or NO_RECORD where no surface covers it (or v lies outside the grid).
uint voxel_record(ivec3 v) {
    if (!inside_levels(v)) return NO_RECORD;
    return voxel_records[voxel_index(v)] - 1u;
}

// The record of the voxel at `local` within level `level`, or NO_RECORD where no surface covers
// it or it lies outside the level's cube.
uint level_record(ivec3 local, int level) {
    if (any(lessThan(local, ivec3(0))) || any(greaterThanEqual(local, ivec3(voxel_grid)))) return NO_RECORD;
    return voxel_records[voxel_index(level_voxel(local, level))] - 1u;
}

// The record of u, a neighbour of voxel v, or NO_RECORD where no surface covers it or it lies
// in another level (outside v's cube).
uint neighbour_record(ivec3 v, ivec3 u) {
    if (u.z < 0 || voxel_level(u) != voxel_level(v)) return NO_RECORD;
    return voxel_record(u);
}

// Where a record's value of side `side` lies in an array of values (VOXEL_SIDES per record).
uint side_value(uint record, int side) {
    return record * uint(VOXEL_SIDES) + uint(side);
}

vec4 unpack_value(uvec2 halves) {
    return vec4(unpackHalf2x16(halves.x), unpackHalf2x16(halves.y));
}

// A side's value of the sky's light (sky_light/): the sky's irradiance E (rgb) and, in a, 1 plus
// the cosine-weighted share of its hemisphere that the sky's cones found open; 0 where the side
// was not traced (it reflects nothing, or its record is new).
vec4 sky_value(vec3 irradiance, float open_share) {
    return vec4(irradiance, 1.0 + open_share);
}

// The open share of a sky value (sky_value); 0 where it was not traced.
float sky_open_share(vec4 value) {
    return max(value.a - 1.0, 0.0);
}

uvec2 pack_value(vec4 value) {
    return uvec2(packHalf2x16(value.xy), packHalf2x16(value.zw));
}
