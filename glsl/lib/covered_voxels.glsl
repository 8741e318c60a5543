// The list of covered voxels (engine/voxel_grid.py: grid.covered), each packed by pack_voxel.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_COVERED) readonly buffer CoveredVoxels { uint covered_count; uint covered[]; };
