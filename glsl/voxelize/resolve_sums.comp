#version 450 core
// Voxel resolve, over the voxels the last voxelization touched, those of the chunk being
// summed (lib/voxel_sums.glsl): divide the fixed-point sums by
// the fragment count into the surface volumes (albedo, normal, emission with the surface offset
// in a; a = 1 marks a covered voxel) and, where surfaces emit, the emission volume specular
// cones read (emission, a = 1 where covered), zero the sums, front-layer keys and slot for the next update, zero the voxel's
// six faces at level 0 of the face views (faces/compose_face_views.comp writes only the faces its new
// surface covers), and list the voxels that were empty before and are covered now, for the new
// covered list.
#include "lib/voxel_sums.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_ALBEDO_OUT, rgba16f) uniform image3D albedo_out;
layout(binding = IMG_NORMAL_OUT, rgba16f) uniform writeonly image3D normal_out;
layout(binding = IMG_EMISSION_OUT, rgba16f) uniform writeonly image3D emission_out;
layout(binding = IMG_CONE_EMISSION_OUT, rgba16f) uniform writeonly image3D cone_emission_out;
layout(binding = IMG_TOUCHED_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
layout(std430, binding = SSBO_COVERED_NEXT) buffer NextCovered { uint next_count; uint next_covered[]; };

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
    bool was_covered = imageLoad(albedo_out, v).a > 0.0;
    if (count == 0u) {  // every surface left this voxel
        imageStore(albedo_out, v, vec4(0.0));
        imageStore(normal_out, v, vec4(0.0));
        imageStore(emission_out, v, vec4(0.0));
        if (voxel_emitters) imageStore(cone_emission_out, v, vec4(0.0));
    } else {
        float samples = float(min(count, VOXEL_MAX_FRAGMENTS));
        float to_unit = 1.0 / (samples * VOXEL_UNIT_SCALE);
        vec3 albedo = vec3(unit_sum(i, SUM_ALBEDO_R), unit_sum(i, SUM_ALBEDO_G), unit_sum(i, SUM_ALBEDO_B)) * to_unit;
        vec3 normal = vec3(unit_sum(i, SUM_NORMAL_X), unit_sum(i, SUM_NORMAL_Y), unit_sum(i, SUM_NORMAL_Z)) * to_unit;
        float offset = unit_sum(i, SUM_OFFSET) * to_unit;
        vec3 emission = vec3(emission_sum(i, SUM_EMISSION_R, SUM_EMISSION_CARRY_R),
                             emission_sum(i, SUM_EMISSION_G, SUM_EMISSION_CARRY_G),
                             emission_sum(i, SUM_EMISSION_B, SUM_EMISSION_CARRY_B)) / (samples * VOXEL_EMISSION_SCALE);
        // The mean normal keeps its length (|mean of unit normals| < 1: spread normals). The
        // surface point c + n t along the normalized mean normal n has mean(dot(p_i - c - n t,
        // n_i)) = 0, so t = mean(offset_i) / |mean normal|, within the voxel.
        float coherence = length(normal);
        float surface_offset = coherence > 0.0 ? clamp(offset / coherence, -0.87, 0.87) : 0.0;
        imageStore(albedo_out, v, vec4(albedo, 1.0));
        imageStore(normal_out, v, vec4(normal, 1.0));
        imageStore(emission_out, v, vec4(emission, surface_offset));
        if (voxel_emitters) imageStore(cone_emission_out, v, vec4(emission, 1.0));
        if (!was_covered) APPEND(next_count, next_covered, pack_voxel(v));
    }
    for (int channel = 0; channel < VOXEL_SUM_CHANNELS; ++channel) voxel_sums[sum_entry(i, channel)] = 0u;
    voxel_slots[voxel_index(v)] = 0u;
    for (int f = 0; f < VOXEL_FACES; ++f) {
        front_keys[key_entry(i, f)] = 0u;
        imageStore(faces_out, face_texel(v, f, voxel_grid), vec4(0.0));
    }
}
