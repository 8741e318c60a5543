#version 450 core
// Voxel resolve, over the voxels the last voxelization touched, those of the chunk being
// summed (lib/voxel_sums.glsl), in two dispatches. First (`freeing`) the voxels every surface
// left give their records back to the pool (engine/voxels/records.py), and the covered list
// reads NO_VOXEL at them; then each covered voxel takes a record where it had none (the covered
// list holds it at that record, and it is listed as newly covered), and the
// fixed-point sums divided by the fragment count become its surfaces, a side per orientation
// (VOXEL_SIDES): albedo, mean normal and opacity (summed, not divided), emission with the
// surface offset in a. Both zero the sums and the front layers' keys and counts for the next
// update and put back the voxel's word of the record index (its record now, or
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

float emission_sum(uint low, uint carry) {
    return float(carry) * 4294967296.0 + float(low);
}

// Side `side` of the voxel's record: the surface of the fragments of the orientations in
// `orientations` (bit k: orientation k), their sums divided by their count (zero where they
// have none).
void resolve_side(int i, uint orientations, uint record, int side, bool two_sides) {
    uint sums[VOXEL_SUM_CHANNELS];
    for (int channel = 0; channel < VOXEL_SUM_CHANNELS; ++channel) {
        sums[channel] = 0u;
        for (int orientation = 0; orientation < VOXEL_SIDES; ++orientation)
            if ((orientations & (1u << orientation)) != 0u) sums[channel] += voxel_sums[sum_entry(i, orientation, channel)];
    }
    uint at = side_value(record, side);
    uint count = sums[SUM_COUNT];
    if (count == 0u) {
        albedo_out[at] = uvec2(0u);
        normal_out[at] = uvec2(0u);
        emission_out[at] = uvec2(0u);
        return;
    }
    float samples = float(min(count, VOXEL_MAX_FRAGMENTS));
    float to_unit = 1.0 / (samples * VOXEL_UNIT_SCALE);
    vec3 albedo = vec3(float(int(sums[SUM_ALBEDO_R])), float(int(sums[SUM_ALBEDO_G])), float(int(sums[SUM_ALBEDO_B]))) * to_unit;
    vec3 normal = vec3(float(int(sums[SUM_NORMAL_X])), float(int(sums[SUM_NORMAL_Y])), float(int(sums[SUM_NORMAL_Z]))) * to_unit;
    float offset = float(int(sums[SUM_OFFSET])) * to_unit;
    // The share of the voxel's face its surfaces cover (their fragments' pixel coverage times
    // their opacity, summed), at most 1.
    float opacity = min(float(sums[SUM_OPACITY]) / VOXEL_UNIT_SCALE, 1.0);
    vec3 emission = vec3(emission_sum(sums[SUM_EMISSION_R], sums[SUM_EMISSION_CARRY_R]),
                         emission_sum(sums[SUM_EMISSION_G], sums[SUM_EMISSION_CARRY_G]),
                         emission_sum(sums[SUM_EMISSION_B], sums[SUM_EMISSION_CARRY_B])) / (samples * VOXEL_EMISSION_SCALE);
    // The mean normal keeps its length (|mean of unit normals| < 1: spread normals). The
    // surface point c + n t along the normalized mean normal n has mean(dot(p_i - c - n t,
    // n_i)) = 0, so t = mean(offset_i) / |mean normal|, within the voxel.
    float coherence = length(normal);
    float surface_offset = coherence > 0.0 ? clamp(offset / coherence, -0.87, 0.87) : 0.0;
    albedo_out[at] = pack_value(vec4(albedo, 1.0));
    normal_out[at] = pack_value(vec4(normal, two_sides ? -opacity : opacity));
    emission_out[at] = pack_value(vec4(emission, surface_offset));
}

// The sum of the unit normals of the fragments of one orientation (xyz, fixed point) and of
// their offsets along them (w).
vec4 orientation_sums(int i, int orientation) {
    return vec4(float(int(voxel_sums[sum_entry(i, orientation, SUM_NORMAL_X)])), float(int(voxel_sums[sum_entry(i, orientation, SUM_NORMAL_Y)])),
                float(int(voxel_sums[sum_entry(i, orientation, SUM_NORMAL_Z)])), float(int(voxel_sums[sum_entry(i, orientation, SUM_OFFSET)])));
}

// Whether the surfaces of the two orientations face apart: their mean normals opposed (cos <
// -SIDES_APART), and either the plane of orientation 0 in front of the plane of orientation 1
// along its normal by more than SIDES_GAP voxels (a sheet's two faces, a thin slab) or most of
// both from double-sided materials (a leaf, a banner: one surface seen from both sides).
// Other surfaces that touch (a box standing on a floor: the floor under it and its bottom) are
// one side, as what lies between them is closed.
bool sides_apart(vec4 a, vec4 b, bool double_sided) {
    float length_a = length(a.xyz), length_b = length(b.xyz);
    if (length_a <= 0.0 || length_b <= 0.0 || dot(a.xyz, b.xyz) >= -SIDES_APART * length_a * length_b) return false;
    vec3 n_a = a.xyz / length_a, n_b = b.xyz / length_b;
    // Each plane at centre + n t, t = sum of offsets / |sum of normals| (as resolve_side places it).
    float gap = a.w / length_a - b.w / length_b * dot(n_b, n_a);
    return gap > SIDES_GAP || double_sided;
}

void main() {
    uint place = gl_GlobalInvocationID.x;
    if (place >= LISTED(touched_count, touched)) return;
    int i = chunk_slot(place);
    if (i < 0) return;  // resolved with its own chunk
    ivec3 v = unpack_voxel(touched[place]);
    uint counts[2] = uint[2](voxel_sums[sum_entry(i, 0, SUM_COUNT)], voxel_sums[sum_entry(i, 1, SUM_COUNT)]);
    uint count = counts[0] + counts[1];
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
        if (record != NO_RECORD) {
            // Two sides where the orientations' surfaces face apart (sides_apart), side 0 the
            // orientation most fragments have (orientation 0 on a tie); one side, both
            // orientations together, where they do not (an edge where a floor meets a wall).
            bool double_sided = 2u * voxel_sums[sum_entry(i, 0, SUM_DOUBLE_SIDED)] >= counts[0]
                                && 2u * voxel_sums[sum_entry(i, 1, SUM_DOUBLE_SIDED)] >= counts[1];
            bool apart = counts[0] > 0u && counts[1] > 0u
                         && sides_apart(orientation_sums(i, 0), orientation_sums(i, 1), double_sided);
            int first = counts[1] > counts[0] ? 1 : 0;
            resolve_side(i, apart ? 1u << first : 3u, record, 0, apart);
            resolve_side(i, apart ? 1u << (1 - first) : 0u, record, 1, false);
        }
    }
    for (int orientation = 0; orientation < VOXEL_SIDES; ++orientation)
        for (int channel = 0; channel < VOXEL_SUM_CHANNELS; ++channel) voxel_sums[sum_entry(i, orientation, channel)] = 0u;
    voxel_records[voxel_index(v)] = record + 1u;  // its record, no longer flagged (0: none)
    for (int f = 0; f < VOXEL_FACES; ++f) front_keys[key_entry(i, f)] = front_keys[count_entry(i, f)] = 0u;
}
