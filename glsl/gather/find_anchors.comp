#version 450 core
// Which covered voxels trace the diffuse gather, and which anchors the others take it from
// (lib/gather_anchors.glsl): per voxel ANCHOR_SELF, ANCHOR_FINER beneath a finer level, or the
// bits of its anchor neighbours (none where it reflects no light). Runs when the voxels
// change: over the voxels whose records were marked stale (gather/mark_stale_anchors.comp), or
// over every covered voxel of the levels in `found_levels` (all of them, or those a scroll
// moved and the next coarser ones).
#include "lib/gather_anchors.glsl"
#include "lib/list_append.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_STALE_VOXELS) readonly buffer StaleVoxels { uint stale_count; uint stale[]; };
uniform bool every_voxel;   // false: the stale voxels
uniform uint found_levels;  // bit k: with every_voxel, level k's voxels are found, the others keep theirs

void main() {
    uint k = gl_GlobalInvocationID.x;
    ivec3 v;
    uint record = k;
    if (every_voxel) {
        if (!covered_voxel(k, v) || !in_level_mask(found_levels, v)) return;
    } else {
        if (k >= LISTED(stale_count, stale)) return;
        v = unpack_voxel(stale[k]);
        record = voxel_record(v);
    }
    vec3 n = unpack_value(voxel_normal[side_value(record, 0)]).xyz;
    uint anchors = 0u;
    bool back = back_reflects_light(record);
    if (reflects_light(side_value(record, 0), n) || back) {
        if (beneath_finer_level(v)) {
            anchors = ANCHOR_FINER;
        } else if (back || on_anchor_lattice(v, n)) {  // a two-sided voxel traces both sides
            anchors = ANCHOR_SELF;
        } else {
            vec3 unit = normalize(n);
            float total = 0.0;
            for (int k = 0; k < 26; ++k) {
                ivec3 u = neighbour(v, k);
                uint u_record = neighbour_record(v, u);
                if (u_record == NO_RECORD) continue;
                vec3 n_u = unpack_value(voxel_normal[side_value(u_record, 0)]).xyz;
                if (dot(n, n_u) <= 0.0 || !on_anchor_lattice(u, n_u) || beneath_finer_level(u)
                    || !reflects_light(side_value(u_record, 0), n_u)) continue;
                anchors |= 1u << k;
                total += anchor_weight(v, unit, u, n_u);
            }
            if (total < MIN_ANCHOR_WEIGHT) anchors = ANCHOR_SELF;
        }
    }
    gather_anchors[record] = anchors | (uint(voxel_facing(n)) << ANCHOR_FACING_SHIFT);
}
