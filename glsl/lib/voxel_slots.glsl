// The voxels an update touched (lib/voxel_sums.glsl). While an update runs, a touched voxel's
// word of the record index (lib/voxel_records.glsl) holds TOUCHED_FLAG and its place on the
// touched list (UNLISTED_PLACE: touched past the list's room), and `touched_records` holds, at
// that place, the word it had before (its record + 1, or 0); the resolve puts the voxel's word
// back once it has read its sums. A voxel's sums lie at its slot: its place on the list less
// `chunk_first`, the chunk of the list being summed.
#include "lib/voxel_records.glsl"
#include "lib/list_append.glsl"

layout(std430, binding = SSBO_TOUCHED) buffer TouchedVoxels { uint touched_count; uint touched[]; };
layout(std430, binding = SSBO_TOUCHED_RECORDS) buffer TouchedRecords { uint touched_records[]; };  // per place on the list

// Flag voxel v as touched by this update and list it, once.
void touch_voxel(ivec3 v) {
    uint i = voxel_index(v);
    uint word = voxel_records[i];
    for (;;) {  // flag the word unless another invocation has: it only ever goes from unflagged to flagged
        if ((word & TOUCHED_FLAG) != 0u) return;
        uint seen = atomicCompSwap(voxel_records[i], word, TOUCHED_FLAG | UNLISTED_PLACE);
        if (seen == word) break;
        word = seen;
    }
    uint place = atomicAdd(touched_count, 1u);
    if (place < uint(touched.length())) {
        touched[place] = pack_voxel(v);
        touched_records[place] = word;
        voxel_records[i] = TOUCHED_FLAG | place;
    }
}
