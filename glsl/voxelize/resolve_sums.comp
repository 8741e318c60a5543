#version 450 core
// Voxel resolve, over the voxels the last voxelization touched, those of the chunk being
// summed (lib/voxel_sums.glsl), in two dispatches. First (`freeing`) the voxels every surface
// left give their records back to the pool (engine/voxels/records.py), and the covered list
// reads NO_VOXEL at them; then each covered voxel takes a record where it had none (the covered
// list holds it at that record, and it is listed as newly covered), and the
// fixed-point sums divided by the fragment count become its surface: albedo, mean normal,
// emission with the surface offset in a. Both zero the sums and front-layer keys
// for the next update and put back the voxel's word of the record index (its record now, or
// none: lib/voxel_slots.glsl), so that cones see at once the surfaces it holds, and none where
// it holds none (level 0 is the records: lib/cone.glsl). Freeing first
// keeps the records an update holds at once to the more of the voxels covered before it and
// after it, within each chunk; a voxel the pool has no record for is counted short (the grid
// is then made anew with more room: VoxelizePass.update).
#include "lib/voxel_sums.glsl"
#include "lib/covered_voxels.glsl"
#include "lib/record_pool.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_ALBEDO) writeonly buffer VoxelAlbedo { uvec2 albedo_out[]; };
layout(std430, binding = SSBO_VOXEL_NORMAL) writeonly buffer VoxelNormal { uvec2 normal_out[]; };
layout(std430, binding = SSBO_VOXEL_EMISSION) writeonly buffer VoxelEmission { uvec2 emission_out[]; };
layout(std430, binding = SSBO_NEWLY_COVERED) buffer NewlyCovered { uint new_count; uint newly_covered[]; };
uniform bool freeing;

float unit_sum(int i, int channel) {
    return float(int(voxel_sums[sum_entry(i, channel)]));
}

float emission_sum(int i, int low_channel, int carry_channel) {
    return float(voxel_sums[sum_entry(i, carry_channel)]) * 4294967296.0 + float(voxel_sums[sum_entry(i, low_channel)]);
}

void main() {
    uint place = gl_GlobalInvocationID.x;
    if (place >= LISTED(touched_count, touched)) return;
    int i = chunk_slot(place);
    if (i < 0) return;  // resolved with its own chunk
    ivec3 v = unpack_voxel(touched[place]);
    uint count = voxel_sums[sum_entry(i, SUM_COUNT)];
    if ((count == 0u) != freeing) return;  // resolved in the other dispatch
    uint record = touched_records[place] - 1u;  // NO_RECORD where the voxel was empty
    if (count == 0u) {  // every surface left this voxel
        if (record != NO_RECORD) {
            give_back_record(record);
            covered[record] = NO_VOXEL;
        }
        record = NO_RECORD;
    } else {
        if (record == NO_RECORD) {  // empty before, covered now
            int at = atomicAdd(free_count, -1) - 1;
            if (at >= 0) {
                record = free_records[at];
                covered[record] = pack_voxel(v);
                atomicMax(covered_count, record + 1u);
                APPEND(new_count, newly_covered, pack_voxel(v));
            } else {
                atomicAdd(short_count, 1u);
            }
        }
        float samples = float(min(count, VOXEL_MAX_FRAGMENTS));
        float to_unit = 1.0 / (samples * VOXEL_UNIT_SCALE);
        vec3 albedo = vec3(unit_sum(i, SUM_ALBEDO_R), unit_sum(i, SUM_ALBEDO_G), unit_sum(i, SUM_ALBEDO_B)) * to_unit;
        vec3 normal = vec3(unit_sum(i, SUM_NORMAL_X), unit_sum(i, SUM_NORMAL_Y), unit_sum(i, SUM_NORMAL_Z)) * to_unit;
        float offset = unit_sum(i, SUM_OFFSET) * to_unit;
        // The mean opacity of its surfaces: exactly 1 where all of them are opaque.
        uint opacity_sum = voxel_sums[sum_entry(i, SUM_OPACITY)];
        float opacity = opacity_sum == uint(samples * VOXEL_UNIT_SCALE) ? 1.0 : float(opacity_sum) * to_unit;
        vec3 emission = vec3(emission_sum(i, SUM_EMISSION_R, SUM_EMISSION_CARRY_R),
                             emission_sum(i, SUM_EMISSION_G, SUM_EMISSION_CARRY_G),
                             emission_sum(i, SUM_EMISSION_B, SUM_EMISSION_CARRY_B)) / (samples * VOXEL_EMISSION_SCALE);
        // The mean normal keeps its length (|mean of unit normals| < 1: spread normals). The
        // surface point c + n t along the normalized mean normal n has mean(dot(p_i - c - n t,
        // n_i)) = 0, so t = mean(offset_i) / |mean normal|, within the voxel.
        float coherence = length(normal);
        float surface_offset = coherence > 0.0 ? clamp(offset / coherence, -0.87, 0.87) : 0.0;
        if (record != NO_RECORD) {
            albedo_out[record] = pack_value(vec4(albedo, 1.0));
            normal_out[record] = pack_value(vec4(normal, opacity));
            emission_out[record] = pack_value(vec4(emission, surface_offset));
        }
    }
    for (int channel = 0; channel < VOXEL_SUM_CHANNELS; ++channel) voxel_sums[sum_entry(i, channel)] = 0u;
    voxel_records[voxel_index(v)] = record + 1u;  // its record, no longer flagged (0: none)
    for (int f = 0; f < VOXEL_FACES; ++f) front_keys[key_entry(i, f)] = 0u;
}
