#version 450 core
// The sky's light the image and the light injection read: at each voxel of a list the mean of
// what the cones brought (sky_light/trace_sky_cones.comp at the anchors, gather/interpolate_from_anchors.comp between them)
// over the voxels within SKY_FILTER_RADIUS whose surfaces face alike, and the open share V likewise,
//   E(v) = sum_u W(v, u) E_traced(u) / sum_u W(v, u),
//   W = prod_k (1 - |u_k - v_k| / (R + 1)) facing_weight(n_v, n_u),
// which puts the cone sets of the anchors around v, each offset by its own jitter, together
// into one estimate: no bands where a cone of one shared set crosses an opening's edge.
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_TRACED_SKY_IRRADIANCE) readonly buffer TracedSky { uvec2 sky_traced[]; };  // sky_value where traced or interpolated
layout(std430, binding = SSBO_VOXEL_SKY_IRRADIANCE) writeonly buffer VoxelSkyIrradiance { uvec2 sky_irradiance_out[]; };
// The voxels to filter: every covered one (the covered list, NO_VOXEL at free records), or those
// a voxelization touched.
#include "lib/voxel_list.glsl"
#include "lib/lit_box.glsl"

// Bit k: level k's voxels within the filter's reach of the lit box (lib/lit_box.glsl), where the
// cones were traced again, are filtered, the others keep theirs.
uniform uint lit_levels;

void main() {
    ivec3 v;
    if (!segment_voxel(gl_GlobalInvocationID.x, v)) return;
    if (!in_level_mask(lit_levels, v)) return;  // its neighbours' light did not change
    if (!near_lit_box(voxel_center(v), float(SKY_FILTER_RADIUS + 1) * voxel_extent(v))) return;  // its neighbours and their anchors
    uint record = voxel_record(v);
    if (record == NO_RECORD) return;  // a touched voxel the voxelization emptied
    for (int side = 0; side < VOXEL_SIDES; ++side) {  // each side from its neighbours' sides that face alike
        vec3 n_v = unpack_value(voxel_normal[side_value(record, side)]).xyz;
        vec3 sum = vec3(0.0);
        float total = 0.0, open_share = 0.0;
        if (dot(n_v, n_v) > 0.0) {
            vec3 n = normalize(n_v);
            const float reach = float(SKY_FILTER_RADIUS + 1);
            for (int dz = -SKY_FILTER_RADIUS; dz <= SKY_FILTER_RADIUS; ++dz)
            for (int dy = -SKY_FILTER_RADIUS; dy <= SKY_FILTER_RADIUS; ++dy)
            for (int dx = -SKY_FILTER_RADIUS; dx <= SKY_FILTER_RADIUS; ++dx) {
                ivec3 u = v + ivec3(dx, dy, dz);
                uint neighbour = neighbour_record(v, u);
                if (neighbour == NO_RECORD) continue;  // no surface
                vec3 tent = 1.0 - abs(vec3(dx, dy, dz)) / reach;
                for (int neighbour_side = 0; neighbour_side < VOXEL_SIDES; ++neighbour_side) {
                    uint at = side_value(neighbour, neighbour_side);
                    vec4 traced = unpack_value(sky_traced[at]);
                    if (traced.a <= 0.0) continue;  // not lit by the sky: a surface that reflects nothing
                    vec3 n_u = unpack_value(voxel_normal[at]).xyz;
                    if (dot(n_u, n_u) <= 0.0) continue;
                    float weight = tent.x * tent.y * tent.z * facing_weight(n, n_u);
                    sum += weight * traced.rgb;
                    open_share += weight * sky_open_share(traced);
                    total += weight;
                }
            }
        }
        sky_irradiance_out[side_value(record, side)] = pack_value(total > 0.0 ? sky_value(sum / total, open_share / total) : vec4(0.0));
    }
}
