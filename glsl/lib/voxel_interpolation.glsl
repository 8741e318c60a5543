// What a surface point takes from the voxels around it (the cone-trace pass's pixels, the
// blended surfaces' fragments): the light they gathered, the fraction of the emitters' light
// that reaches them and the sky's light, interpolated.
#include "lib/gbuffer.glsl"
#include "lib/voxel_surface.glsl"
#include "lib/voxel_light.glsl"

// The diffuse gather sum_j w_j Lv(p, w_j) of each voxel, per record (gather/).
layout(std430, binding = SSBO_VOXEL_GATHERED) readonly buffer VoxelGathered { uvec2 voxel_gathered[]; };

// What a point takes from the 8 voxels whose centres surround its point p, each weighted
// trilinearly and by how its surface faces the point's normal n (facing_weight): the diffuse gather
// sum_j w_j Lv(p, w_j) of the voxels that reflect light (`gathered`; `gathered_found` false
// where none faces n), the fraction of the emitters' light that arrives (`emitter_visibility`;
// 1 where no voxel faces n, a thin surface seen from behind) and the environment's irradiance
// (`sky_irradiance`; 0 where no voxel faces n). The voxels are those of the finest level holding
// them (surface_level), blended with the next coarser level's near its border (level_share).
struct VoxelInterpolation {
    vec3 gathered;
    bool gathered_found;
    float emitter_visibility;
    vec3 sky_irradiance;
};

// The weighted sums of the interpolation, over one level or two.
struct VoxelSums {
    vec3 gathered, sky;
    float gathered_total, visibility, surface_total;
};

// Add a side of a voxel (`at`: side_value, its mean normal n_v) at the weight `weight`, times
// how it faces s.
void add_side(inout VoxelSums sums, Surface s, uint at, vec3 n_v, float weight, bool want_gathered, bool want_visibility,
              bool want_sky) {
    vec4 g = want_gathered ? unpack_value(voxel_gathered[at]) : vec4(0.0);
    if (g.a <= 0.0 && !want_visibility && !want_sky) return;  // none that reflects diffuse light
    if (dot(n_v, n_v) <= 0.0) return;  // no surface
    float facing = weight * facing_weight(s.normal, n_v);
    if (g.a > 0.0) {
        sums.gathered += facing * g.rgb;
        sums.gathered_total += facing;
    }
    if (want_visibility) sums.visibility += facing * unpack_value(voxel_emitter_irradiance[at]).a;
    if (want_sky) sums.sky += facing * unpack_value(voxel_sky_irradiance[at]).rgb;
    sums.surface_total += facing;
}

// Add the 8 voxels of `level` around s.position, their weights times `share`.
void add_level_voxels(inout VoxelSums sums, Surface s, int level, float share, bool want_gathered, bool want_visibility,
                      bool want_sky) {
    TrilinearVoxels lookup = trilinear_voxels(level_uvw(s.position, level));
    for (int k = 0; k < 8; ++k) {
        uint record = level_record(lookup.first + corner_offset(k), level);
        if (record == NO_RECORD) continue;  // no surface
        vec4 side_0_normal = unpack_value(voxel_normal[side_value(record, 0)]);
        float weight = share * trilinear_weight(lookup, k);
        for (int side = 0; side < sides_of(side_0_normal); ++side)  // a voxel with two sides: its other one too
            add_side(sums, s, side_value(record, side), side_normal(record, side, side_0_normal).xyz, weight, want_gathered,
                     want_visibility, want_sky);
    }
}

VoxelInterpolation interpolate_voxels(Surface s, bool want_gathered, bool want_visibility, bool want_sky) {
    VoxelSums sums = VoxelSums(vec3(0.0), vec3(0.0), 0.0, 0.0, 0.0);
    int level = surface_level(s.position);
    float share = level_share(s.position, level, 1.0);
    add_level_voxels(sums, s, level, share, want_gathered, want_visibility, want_sky);
    if (share < 1.0) add_level_voxels(sums, s, level + 1, 1.0 - share, want_gathered, want_visibility, want_sky);
    VoxelInterpolation result;
    result.gathered_found = sums.gathered_total > 1e-4;
    result.gathered = result.gathered_found ? sums.gathered / sums.gathered_total : vec3(0.0);
    bool surface_found = sums.surface_total > 1e-4;
    result.emitter_visibility = surface_found ? sums.visibility / sums.surface_total : 1.0;
    result.sky_irradiance = surface_found ? sums.sky / sums.surface_total : vec3(0.0);
    return result;
}
