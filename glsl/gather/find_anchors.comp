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
    vec4 normal = unpack_value(voxel_normal[side_value(record, 0)]);
    vec3 sides[2];
    reflecting_sides(record, normal, false, sides[0], sides[1]);
    bvec2 reflects = bvec2(dot(sides[0], sides[0]) > 0.0, dot(sides[1], sides[1]) > 0.0);
    uint anchors = 0u;
    if (any(reflects)) {
        if (beneath_finer_level(v)) {
            anchors = ANCHOR_FINER;
        } else if (on_anchor_lattice(v, normal.xyz)) {
            anchors = ANCHOR_SELF;
        } else {  // each side that reflects light needs enough weight of anchors facing its way
            vec3 units[2] = vec3[2](reflects.x ? normalize(sides[0]) : vec3(0.0), reflects.y ? normalize(sides[1]) : vec3(0.0));
            vec2 total = vec2(0.0);
            for (int k = 0; k < 26; ++k) {
                ivec3 u = neighbour(v, k);
                uint u_record = neighbour_record(v, u);
                if (u_record == NO_RECORD) continue;
                vec4 u_normal = unpack_value(voxel_normal[side_value(u_record, 0)]);
                if (!on_anchor_lattice(u, u_normal.xyz) || beneath_finer_level(u)) continue;
                vec3 u_sides[2];
                reflecting_sides(u_record, u_normal, false, u_sides[0], u_sides[1]);
                vec2 weight = vec2(0.0);
                for (int side = 0; side < 2; ++side) {
                    if (!reflects[side]) continue;
                    weight[side] = side_anchor_weight(v, units[side], u, u_sides[0]) + side_anchor_weight(v, units[side], u, u_sides[1]);
                }
                if (weight.x + weight.y > 0.0) anchors |= 1u << k;
                total += weight;
            }
            if ((reflects.x && total.x < MIN_ANCHOR_WEIGHT) || (reflects.y && total.y < MIN_ANCHOR_WEIGHT)) anchors = ANCHOR_SELF;
        }
    }
    gather_anchors[record] = anchors | (uint(voxel_facing(normal.xyz)) << ANCHOR_FACING_SHIFT);
}
