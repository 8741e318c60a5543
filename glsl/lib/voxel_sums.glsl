// The voxelizer's per-voxel fixed-point sums (engine/constants.py VOXEL_SUM_CHANNELS): one
// storage block per channel, one uint per voxel of the slab being voxelized (the grid's layers
// slab_first .. slab_first + slab_depth - 1 along z), and the front-layer keys of those voxels.
// Integer sums make the average of a voxel's fragments independent of their order, so a voxel
// resolves to the same bits however often and in whatever order it is rebuilt. The top bit of
// the count marks the voxels the current update touched.
#include "lib/voxel.glsl"

layout(std430, binding = SSBO_VOXEL_SUMS) buffer VoxelSum { uint value[]; } voxel_sums[VOXEL_SUM_CHANNELS];
uniform int slab_first;
uniform int slab_depth;

bool in_slab(ivec3 v) {
    return v.z >= slab_first && v.z < slab_first + slab_depth;
}

// Index of voxel v (in the slab) in the sums.
uint sum_index(ivec3 v) {
    return grid_index(v - ivec3(0, 0, slab_first), voxel_grid);
}

// Texel of voxel v's front-layer key for `face` in the slab's keys (stacked like the face views).
ivec3 front_texel(ivec3 v, int face) {
    return face_texel(v - ivec3(0, 0, slab_first), face, slab_depth);
}
