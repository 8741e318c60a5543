#version 450 core
// The gather of the voxels that are not anchors (lib/gather_anchors.glsl), from the anchors
// gather/find_anchors.comp found around them (those beneath a finer level take the finer
// voxels' after: gather/take_finer_gather.comp):
//   G(v) = sum_u W(v, u) G(u) / sum_u W(v, u),
// each side of the voxel from the sides of its anchors that face its way (the whole value: the
// gather's a = 1, the sky's open share: lib/voxel_records.glsl sky_value); 0 where a side
// reflects no light. Reads and writes one record array:
// the anchors it reads are not among the voxels it writes.
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_GATHERED_OUT) buffer GatheredOut { uvec2 gathered[]; };
layout(std430, binding = SSBO_CLASS_LIST) readonly buffer ClassList { uint class_list[]; };
// The voxels of a list (a class's that are not anchors, or the voxels a voxelization touched)
// whose gather to interpolate: the anchors among them keep theirs. Run `segment_part` of
// `segment_parts` of them (0 of 1: all; the region of the anchors the refinement traced).
#include "lib/list_segment.glsl"
uniform uint segment_part;
uniform uint segment_parts;

void main() {
    uint entry;
    if (!segment_run_entry(gl_GlobalInvocationID.x, segment_part, segment_parts, entry)) return;
    ivec3 v = unpack_voxel(class_list[segment_first() + entry]);
    uint record = voxel_record(v);
    if (record == NO_RECORD || (gather_anchors[record] & (ANCHOR_SELF | ANCHOR_FINER)) != 0u) return;  // empty, traced, or from finer
    uint anchors = gather_anchors[record] & ANCHOR_NEIGHBOURS;
    vec4 normal = unpack_value(voxel_normal[side_value(record, 0)]);
    int sides = sides_of(normal);
    vec3 n[2];
    reflecting_sides(record, normal, anchors != 0u, n[0], n[1]);
    bvec2 wanted = bvec2(anchors != 0u && dot(n[0], n[0]) > 0.0, anchors != 0u && dot(n[1], n[1]) > 0.0);
    for (int side = 0; side < 2; ++side) n[side] = wanted[side] ? normalize(n[side]) : vec3(0.0);
    // Each side from the anchors' sides facing its way, every anchor's sides read once.
    vec4 sum[2] = vec4[2](vec4(0.0), vec4(0.0));
    vec2 total = vec2(0.0);
    for (uint bits = anchors; bits != 0u; bits &= bits - 1u) {
        ivec3 u = neighbour(v, findLSB(bits));
        uint anchor = voxel_record(u);  // recorded anchors are covered
        vec3 u_sides[2];
        reflecting_sides(anchor, unpack_value(voxel_normal[side_value(anchor, 0)]), true, u_sides[0], u_sides[1]);
        for (int side = 0; side < sides; ++side) {
            if (!wanted[side]) continue;
            for (int t = 0; t < 2; ++t) {
                float weight = side_anchor_weight(v, n[side], u, u_sides[t]);
                if (weight > 0.0) sum[side] += weight * unpack_value(gathered[side_value(anchor, t)]);
                total[side] += weight;
            }
        }
    }
    for (int side = 0; side < sides; ++side)  // total >= MIN_ANCHOR_WEIGHT where wanted
        gathered[side_value(record, side)] = pack_value(wanted[side] ? sum[side] / total[side] : vec4(0.0));
}
