// The resolved surface of each voxel (written by voxelize/resolve_sums.comp): reflectance, mean
// normal, emission, and the point on the surface nearest the voxel centre.
#include "lib/voxel_records.glsl"

layout(std430, binding = SSBO_VOXEL_ALBEDO) readonly buffer VoxelAlbedo { uvec2 voxel_albedo[]; };       // rgb, a = 1
layout(std430, binding = SSBO_VOXEL_NORMAL) readonly buffer VoxelNormal { uvec2 voxel_normal[]; };       // xyz mean normal, w = 1
layout(std430, binding = SSBO_VOXEL_EMISSION) readonly buffer VoxelEmission { uvec2 voxel_emission[]; }; // rgb, a = surface offset in voxels

// Voxel v's mean normal (zero where no surface covers it).
vec3 voxel_mean_normal(ivec3 v) {
    return RECORD_VALUE(voxel_normal, voxel_record(v)).xyz;
}

struct VoxelSurface {
    bool covered;
    vec3 albedo;       // reflectance (lib/brdf.glsl layered_albedo), averaged over the voxel's fragments
    vec3 mean_normal;  // mean of the fragments' unit normals: its length is their coherence
    vec3 position;     // the voxel centre moved along the normal onto the (mean) surface
    vec3 emission;     // radiance of the front sides, W/(m^2 sr)
};

VoxelSurface voxel_surface(ivec3 v) {
    VoxelSurface s;
    uint record = voxel_record(v);
    vec4 emission = RECORD_VALUE(voxel_emission, record);
    s.covered = record != NO_RECORD;
    s.albedo = RECORD_VALUE(voxel_albedo, record).rgb;
    s.mean_normal = RECORD_VALUE(voxel_normal, record).xyz;
    s.emission = emission.rgb;
    float length_n = length(s.mean_normal);
    // Surface point = centre + n * mean(dot(p_i - centre, n_i)): the centre projected onto a plane.
    s.position = voxel_center(v) + (length_n > 0.0 ? s.mean_normal / length_n * emission.a * voxel_size : vec3(0.0));
    return s;
}
