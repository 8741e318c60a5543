// The voxels an update touched (lib/voxel_sums.glsl): `voxel_slots` holds, per voxel of the
// grid, its place on the touched list + 1 while an update runs (0: not touched;
// UNLISTED_VOXEL: touched past the list's room), and 0 again once the resolve has read its sums.
// A voxel's sums lie at its slot: its place on the list less `chunk_first`, the chunk of the
// list being summed.
#include "lib/voxel.glsl"
#include "lib/list_append.glsl"

layout(std430, binding = SSBO_VOXEL_SLOTS) buffer VoxelSlots { uint voxel_slots[]; };  // per voxel of the grid
layout(std430, binding = SSBO_TOUCHED) buffer TouchedVoxels { uint touched_count; uint touched[]; };

// Flag voxel v as touched by this update and list it, once.
void touch_voxel(ivec3 v) {
    uint i = voxel_index(v);
    if (atomicCompSwap(voxel_slots[i], 0u, UNLISTED_VOXEL) != 0u) return;
    uint place = atomicAdd(touched_count, 1u);
    if (place < uint(touched.length())) {
        touched[place] = pack_voxel(v);
        voxel_slots[i] = place + 1u;
    }
}
