#version 450 core
// Marks ANCHOR_STALE the gather-anchor records (lib/gather_anchors.glsl) of the voxels a
// voxelization touched and of their 26 neighbours, the records it may have changed, and lists
// each of those voxels once for gather/find_anchors.comp (which leaves no record stale). An
// empty neighbour whose record was already none keeps it: finding it again would give none. So
// the list holds voxels covered now or before, at most the room of two covered lists.
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
        if (any(lessThan(u, ivec3(0))) || any(greaterThanEqual(u, ivec3(voxel_grid)))) continue;
        uint record = atomicExchange(gather_anchors[voxel_index(u)], ANCHOR_STALE);
        if (record == ANCHOR_STALE) continue;  // listed by another invocation
        if (record == 0u && voxel_record(u) == NO_RECORD) gather_anchors[voxel_index(u)] = 0u;
        else APPEND(stale_count, stale, pack_voxel(u));
    }
}
