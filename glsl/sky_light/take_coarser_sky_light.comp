#version 450 core
// The sky's light at the voxels a scrolled clipmap level took in, taken from the next coarser
// level, which holds the same surfaces in voxels twice as wide: at each voxel's surface point the
// trilinear lookup of the coarser level's filtered sky light over its voxels that face alike,
//   E(v) = sum_u t_u facing_weight(n_v, n_u) E(u) / sum_u t_u facing_weight(n_v, n_u)
// (t_u: u's trilinear weight), written as the voxel's traced and filtered light. The level's
// voxels are lit by their own cones once the camera rests (engine/frame/schedule.py, light_voxels).
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_TRACED_SKY_IRRADIANCE) writeonly buffer TracedSky { uvec2 sky_traced_out[]; };
layout(std430, binding = SSBO_VOXEL_SKY_IRRADIANCE) buffer VoxelSkyIrradiance { uvec2 sky_irradiance[]; };
// The voxels a voxelization touched.
#include "lib/voxel_list.glsl"

uniform uint lit_levels;  // bit k: level k's voxels take their light from level k + 1

void main() {
    ivec3 v;
    if (!segment_voxel(gl_GlobalInvocationID.x, v)) return;
    if (!in_level_mask(lit_levels, v)) return;
    uint record = voxel_record(v);
    if (record == NO_RECORD) return;  // a touched voxel the voxelization emptied
    for (int side = 0; side < VOXEL_SIDES; ++side) {
        VoxelSurface s = voxel_surface(v, record, side);
        vec3 sum = vec3(0.0);
        float total = 0.0;
        if (dot(s.mean_normal, s.mean_normal) > 0.0) {
            vec3 n = normalize(s.mean_normal);
            int coarser = voxel_level(v) + 1;
            TrilinearVoxels lookup = trilinear_voxels(level_uvw(s.position, coarser));
            for (int k = 0; k < 8; ++k) {
                uint neighbour = level_record(lookup.first + corner_offset(k), coarser);
                if (neighbour == NO_RECORD) continue;  // no surface, or outside the coarser cube
                for (int neighbour_side = 0; neighbour_side < VOXEL_SIDES; ++neighbour_side) {
                    uint at = side_value(neighbour, neighbour_side);
                    vec4 coarse = unpack_value(sky_irradiance[at]);
                    vec3 n_u = unpack_value(voxel_normal[at]).xyz;
                    if (coarse.a <= 0.0 || dot(n_u, n_u) <= 0.0) continue;
                    float weight = trilinear_weight(lookup, k) * facing_weight(n, n_u);
                    sum += weight * coarse.rgb;
                    total += weight;
                }
            }
        }
        uvec2 light = pack_value(total > 0.0 ? vec4(sum / total, 1.0) : vec4(0.0));
        sky_traced_out[side_value(record, side)] = light;
        sky_irradiance[side_value(record, side)] = light;
    }
}
