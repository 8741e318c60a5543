#version 450 core
// The diffuse gather of each anchor among the voxels of a list segment (an interleave class's
// anchors, or the touched voxels: lib/gather_anchors.glsl), with the
// lecture's 6 cones from its surface point along its mean normal: G = sum_j w_j L(p, w_j). It
// feeds the next bounce (faces/compose_face_views.comp) and the image (cone_trace/shade_pixels.frag interpolates it per
// pixel); the other voxels take theirs from the anchors (gather/interpolate_from_anchors.comp). a = 1: a voxel that
// reflects light (the others hold 0).
// Under a sky (SKY) the sky's cones decide how much of the hemisphere is open, V
// (sky_light/trace_sky_cones.comp), and the cones here only what the rest holds: where their
// occlusion A = sum_j w_j a_j exceeds 1 - V, G takes (1 - V) / A of what they met. The diffuse
// cones read coarser than the sky's and take in the walls beside an opening in directions the
// sky's cones see open; counted by both, that part of the hemisphere would bring the walls'
// light and the sky's.
#include "lib/voxel_surface.glsl"
#include "lib/cone.glsl"
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_GATHERED_OUT) writeonly buffer GatheredOut { uvec2 gathered_out[]; };
layout(std430, binding = SSBO_CLASS_LIST) readonly buffer ClassList { uint class_list[]; };
#ifdef SKY
// The sky's light at each side (sky_light/filter_sky_light.comp), for its open share.
layout(std430, binding = SSBO_VOXEL_SKY_IRRADIANCE) readonly buffer VoxelSkyIrradiance { uvec2 voxel_sky_irradiance[]; };
#endif
// The segment of the class list to gather.
#include "lib/list_segment.glsl"
// Its entries to trace: run `segment_part` of `segment_parts` (0 of 1: all; the viewer's
// refinement with the tiled cones spreads the anchors over several frames,
// engine/frame/schedule.py).
uniform uint segment_part;
uniform uint segment_parts;

void main() {
    uint entry;
    if (!segment_run_entry(gl_GlobalInvocationID.x, segment_part, segment_parts, entry)) return;
    ivec3 v = unpack_voxel(class_list[segment_first() + entry]);
    uint record = voxel_record(v);
    if (record == NO_RECORD || (gather_anchors[record] & ANCHOR_SELF) == 0u) return;  // empty, or interpolated (GatherPass.fill)
    VoxelSurface s = voxel_surface(v, record, 0);  // side 0 says how many sides there are
    int sides = s.sides;
    for (int side = 0; side < sides; ++side) {  // each side from its own surface
        if (side > 0) s = voxel_surface(v, record, side);
        if (dot(s.mean_normal, s.mean_normal) <= 0.0) continue;  // no surface of this side
        vec3 n = normalize(s.mean_normal);
        vec3 start = side_cone_start(s, n, v, sides);
        vec4 gathered = trace_diffuse(start, n, voxel_level(v), 1e9, VOXEL_DIFFUSE_READING);
#ifdef SKY
        // G *= min(1, (1 - V) / A): the surfaces met cover at most the share the sky leaves.
        float open_share = sky_open_share(unpack_value(voxel_sky_irradiance[side_value(record, side)]));
        if (gathered.a > 1.0 - open_share) gathered.rgb *= (1.0 - open_share) / gathered.a;
#endif
        gathered_out[side_value(record, side)] = pack_value(vec4(gathered.rgb, 1.0));
    }
}
