#version 450 core
// Marks ANCHOR_STALE the gather-anchor records (lib/gather_anchors.glsl) of the voxels a
// voxelization touched and of their 26 neighbours, the records it may have changed, and lists
// each of those voxels once for gather/find_anchors.comp (which leaves no record stale).
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_TOUCHED) readonly buffer TouchedVoxels { uint touched_count; uint touched[]; };
layout(std430, binding = SSBO_STALE_VOXELS) buffer StaleVoxels { uint stale_count; uint stale[]; };

void main() {
    if (gl_GlobalInvocationID.x >= touched_count) return;
    ivec3 v = unpack_voxel(touched[gl_GlobalInvocationID.x]);
    for (int k = 0; k < 27; ++k) {
        ivec3 u = v + ivec3(k % 3, (k / 3) % 3, k / 9) - 1;
        if (all(greaterThanEqual(u, ivec3(0))) && all(lessThan(u, ivec3(voxel_grid)))
            && atomicExchange(gather_anchors[voxel_index(u)], ANCHOR_STALE) != ANCHOR_STALE)
            stale[atomicAdd(stale_count, 1u)] = pack_voxel(u);
    }
}
