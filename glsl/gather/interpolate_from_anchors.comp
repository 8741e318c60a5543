#version 450 core
// The gather of the voxels that are not anchors (lib/gather_anchors.glsl), from the anchors
// gather/find_anchors.comp found around them (those beneath a finer level take the finer
// voxels' after: gather/take_finer_gather.comp):
//   G(v) = sum_u W(v, u) G(u) / sum_u W(v, u),
// 0 where the voxel reflects no light (no anchors recorded). Reads and writes one record array:
// the anchors it reads are not among the voxels it writes.
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_GATHERED_OUT) buffer GatheredOut { uvec2 gathered[]; };
layout(std430, binding = SSBO_CLASS_LIST) readonly buffer ClassList { uint class_list[]; };
// The voxels of a list (a class's that are not anchors, or the voxels a voxelization touched)
// whose gather to interpolate: the anchors among them keep theirs.
#include "lib/list_segment.glsl"

void main() {
    if (gl_GlobalInvocationID.x >= segment_count()) return;
    ivec3 v = unpack_voxel(class_list[segment_first() + gl_GlobalInvocationID.x]);
    uint record = voxel_record(v);
    if (record == NO_RECORD || (gather_anchors[record] & (ANCHOR_SELF | ANCHOR_FINER)) != 0u) return;  // empty, traced, or from finer
    uint anchors = gather_anchors[record] & ANCHOR_NEIGHBOURS;
    vec4 result = vec4(0.0);
    if (anchors != 0u) {
        vec3 n = normalize(unpack_value(voxel_normal[side_value(record, 0)]).xyz);
        vec3 sum = vec3(0.0);
        float total = 0.0;
        for (; anchors != 0u; anchors &= anchors - 1u) {
            ivec3 u = neighbour(v, findLSB(anchors));
            uint anchor = voxel_record(u);  // recorded anchors are covered
            float weight = anchor_weight(v, n, u, unpack_value(voxel_normal[side_value(anchor, 0)]).xyz);
            sum += weight * unpack_value(gathered[side_value(anchor, 0)]).rgb;
            total += weight;
        }
        result = vec4(sum / total, 1.0);  // total >= MIN_ANCHOR_WEIGHT
    }
    gathered[side_value(record, 0)] = pack_value(result);  // a voxel that interpolates has one side
}
