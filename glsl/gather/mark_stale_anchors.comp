#version 450 core
// Marks ANCHOR_STALE the gather anchors (lib/gather_anchors.glsl) of the covered voxels among
// those a voxelization touched and their 26 neighbours, the anchors it may have changed, and
// lists each of those voxels once for gather/find_anchors.comp (which leaves none stale). Empty
// voxels hold no anchors (nor a record): the list holds covered voxels only.
#include "lib/gather_anchors.glsl"
#include "lib/list_append.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_TOUCHED) readonly buffer TouchedVoxels { uint touched_count; uint touched[]; };
layout(std430, binding = SSBO_STALE_VOXELS) buffer StaleVoxels { uint stale_count; uint stale[]; };

void main() {
    if (gl_GlobalInvocationID.x >= LISTED(touched_count, touched)) return;
    ivec3 v = unpack_voxel(touched[gl_GlobalInvocationID.x]);
    for (int k = 0; k < 27; ++k) {
        ivec3 u = v + ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
        uint record = neighbour_record(v, u);
        if (record == NO_RECORD) continue;
        if (atomicExchange(gather_anchors[record], ANCHOR_STALE) == ANCHOR_STALE) continue;  // listed by another invocation
        APPEND(stale_count, stale, pack_voxel(u));
    }
}
