// The voxelizer's per-voxel fixed-point sums (engine/constants.py VOXEL_SUM_CHANNELS): one
// storage block per channel, one uint per voxel. Integer sums make the average of a voxel's
// fragments independent of their order, so a voxel resolves to the same bits however often
// and in whatever order it is rebuilt. The top bit of the count marks the voxels the current
// update touched.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_VOXEL_SUMS) buffer VoxelSum { uint value[]; } voxel_sums[VOXEL_SUM_CHANNELS];
