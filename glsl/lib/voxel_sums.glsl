// The voxelizer's fixed-point sums (engine/core/constants.py VOXEL_SUM_CHANNELS) and front-layer
// keys (one per facing direction) of the voxels an update touched, a record per voxel at its
// slot (lib/voxel_slots.glsl). The sums have room for a chunk of the touched list (sum_room);
// an update touching more voxels sums them chunk after chunk. Integer sums make the average of
// a voxel's fragments independent of their order, so a voxel resolves to the same bits however
// often and in whatever order it is rebuilt.
#include "lib/voxel_slots.glsl"

layout(std430, binding = SSBO_VOXEL_SUMS) buffer VoxelSums { uint voxel_sums[]; };  // VOXEL_SUM_CHANNELS per slot and orientation
layout(std430, binding = SSBO_FRONT_KEYS) buffer FrontKeys { uint front_keys[]; };  // VOXEL_FACES per slot
uniform uint chunk_first;

uint sum_room() {
    return uint(voxel_sums.length()) / uint(VOXEL_SIDES * VOXEL_SUM_CHANNELS);
}

// The slot of a place on the touched list in this chunk's sums; -1 where it lies in another.
int chunk_slot(uint place) {
    uint slot = place - chunk_first;  // wraps past sum_room() below chunk_first
    return slot < sum_room() ? int(slot) : -1;
}

// The slot of voxel v's sums in this chunk; -1 where the update did not touch it (or it lies
// in another chunk, or off the touched list, or was resolved).
int sum_slot(ivec3 v) {
    uint word = voxel_records[voxel_index(v)];
    uint place = word & ~TOUCHED_FLAG;
    return (word & TOUCHED_FLAG) == 0u || place == UNLISTED_PLACE ? -1 : chunk_slot(place);
}

// A channel of the sums of the fragments of one orientation (0: the dominant component of their
// normal positive, 1: negative); the resolve makes the orientation most of them have side 0.
uint sum_entry(int slot, int orientation, int channel) {
    return (uint(slot) * uint(VOXEL_SIDES) + uint(orientation)) * uint(VOXEL_SUM_CHANNELS) + uint(channel);
}

uint key_entry(int slot, int face) {
    return uint(slot) * uint(VOXEL_FACES) + uint(face);
}
