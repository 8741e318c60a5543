#version 450 core
// The gather of level `level`'s voxels beneath the finer level (lib/gather_anchors.glsl:
// beneath_finer_level), from the 8 finer voxels c that tile each voxel V:
//   G(V) = sum_c W_c G(c) / sum_c W_c,   W_c = facing_weight(n_V, n_c) over the c that reflect light
// (their value's a > 0), their plain mean where none faces V's way; where none of the 8
// reflects light, from the finer voxels around them; 0 where none does. The whole value (the
// gather's a = 1, the sky's open share: lib/voxel_records.glsl sky_value). The finer level's
// gather is complete before (GatherPass.fill runs the levels in order).
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_GATHERED_OUT) buffer GatheredOut { uvec2 gathered[]; };
layout(std430, binding = SSBO_CLASS_LIST) readonly buffer ClassList { uint class_list[]; };
// The voxels of a list whose gather to take from the finer level: those of `level` among them.
#include "lib/list_segment.glsl"
uniform int level;

// The sums of the finer values: weighted by how alike they face, and plainly; and their weights.
struct FinerSums {
    vec4 faced, plain;
    float faced_weight, plain_weight;
};

// Adds finer voxel `finer`'s value to the sums, weighted by how alike it faces unit normal n and
// plainly, where it reflects light.
void add_finer(ivec3 finer, vec3 n, inout FinerSums sums) {
    uint record = level_record(finer, level - 1);
    if (record == NO_RECORD) return;
    for (int side = 0; side < VOXEL_SIDES; ++side) {
        uint at = side_value(record, side);
        vec4 g = unpack_value(gathered[at]);
        vec3 n_u = unpack_value(voxel_normal[at]).xyz;
        if (g.a <= 0.0 || dot(n_u, n_u) <= 0.0) continue;  // reflects no light, or no surface of this side
        float weight = facing_weight(n, n_u);
        sums.faced += weight * g;
        sums.faced_weight += weight;
        sums.plain += g;
        sums.plain_weight += 1.0;
    }
}

void main() {
    if (gl_GlobalInvocationID.x >= segment_count()) return;
    ivec3 v = unpack_voxel(class_list[segment_first() + gl_GlobalInvocationID.x]);
    if (voxel_level(v) != level) return;
    uint record = voxel_record(v);
    if (record == NO_RECORD || (gather_anchors[record] & ANCHOR_FINER) == 0u) return;
    ivec3 first = first_finer_voxel(v);
    for (int side = 0; side < VOXEL_SIDES; ++side) {
        vec3 n_side = unpack_value(voxel_normal[side_value(record, side)]).xyz;
        if (dot(n_side, n_side) <= 0.0) continue;  // no surface of this side
        vec3 n = normalize(n_side);
        FinerSums sums = FinerSums(vec4(0.0), vec4(0.0), 0.0, 0.0);
        for (int k = 0; k < 8; ++k) add_finer(first + corner_offset(k), n, sums);
        if (sums.plain_weight == 0.0) {
            // None of the 8 reflects light (a surface on V's side that the finer voxelization put
            // in the voxels beyond): the 56 finer voxels around them.
            for (int k = 0; k < 64; ++k) {
                ivec3 offset = ivec3(k & 3, (k >> 2) & 3, k >> 4) - 1;  // -1..2 per axis
                bool around = any(lessThan(offset, ivec3(0))) || any(greaterThan(offset, ivec3(1)));
                if (around) add_finer(first + offset, n, sums);
            }
        }
        vec4 value = sums.faced_weight > 0.0 ? sums.faced / sums.faced_weight
                   : sums.plain_weight > 0.0 ? sums.plain / sums.plain_weight : vec4(0.0);
        gathered[side_value(record, side)] = pack_value(value);
    }
}
