// The voxelizer's fixed-point sums (engine/core/constants.py VOXEL_SUM_CHANNELS), and front-layer
// keys and fragment counts (one of each per facing direction) of the voxels an update touched, a record per voxel at its
// slot (lib/voxel_slots.glsl). The sums have room for a chunk of the touched list (sum_room);
// an update touching more voxels sums them chunk after chunk. Integer sums make the average of
// a voxel's fragments independent of their order, so a voxel resolves to the same bits however
// often and in whatever order it is rebuilt.
#include "lib/voxel_slots.glsl"

layout(std430, binding = SSBO_VOXEL_SUMS) buffer VoxelSums { uint voxel_sums[]; };  // VOXEL_SUM_CHANNELS per slot and orientation
layout(std430, binding = SSBO_FRONT_KEYS) buffer FrontKeys { uint front_keys[]; };  // 2 VOXEL_FACES per slot: keys, counts
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

// A channel of the sums of the fragments of one orientation (fragment_orientation); the resolve
// makes the orientation most of them have side 0.
uint sum_entry(int slot, int orientation, int channel) {
    return (uint(slot) * uint(VOXEL_SIDES) + uint(orientation)) * uint(VOXEL_SUM_CHANNELS) + uint(channel);
}

// The front-layer key of the fragments facing `face` (facing_face), and their count.
uint key_entry(int slot, int face) {
    return uint(slot) * uint(2 * VOXEL_FACES) + uint(face);
}

uint count_entry(int slot, int face) {
    return key_entry(slot, face) + uint(VOXEL_FACES);
}

// The orientation of a fragment of normal n: 0 where n faces the way of the facing most of the
// voxel's fragments have (n . axis >= 0, the lowest facing on a tie), 1 where it faces against
// it. A sheet's two faces fall apart whatever way it leans, and the surfaces of one face of a
// folded one stay together (its facings split by the dominant component's sign would mix both
// faces in each orientation where its normal crosses a diagonal between two axes).
int fragment_orientation(int slot, vec3 n) {
    int reference = 0;
    uint most = front_keys[count_entry(slot, 0)];
    for (int f = 1; f < VOXEL_FACES; ++f) {
        uint count = front_keys[count_entry(slot, f)];
        if (count > most) {
            most = count;
            reference = f;
        }
    }
    float along = n[reference >> 1];
    return ((reference & 1) == 0 ? along : -along) < 0.0 ? 1 : 0;
}
