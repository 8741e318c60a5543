// The resolved surface of each voxel (written by voxelize/resolve_sums.comp): reflectance, mean
// normal, emission, and the point on the surface nearest the voxel centre.
#include "lib/voxel_records.glsl"

layout(std430, binding = SSBO_VOXEL_ALBEDO) readonly buffer VoxelAlbedo { uvec2 voxel_albedo[]; };       // rgb, a = 1
layout(std430, binding = SSBO_VOXEL_NORMAL) readonly buffer VoxelNormal { uvec2 voxel_normal[]; };       // xyz mean normal, w: opacity (blended surfaces' mean alpha, else 1)
layout(std430, binding = SSBO_VOXEL_EMISSION) readonly buffer VoxelEmission { uvec2 voxel_emission[]; }; // rgb, a = surface offset in voxels

struct VoxelSurface {
    vec3 albedo;       // reflectance (lib/brdf.glsl layered_albedo), averaged over the voxel's fragments
    vec3 mean_normal;  // mean of the fragments' unit normals: its length is their coherence
    vec3 position;     // the voxel centre moved along the normal onto the (mean) surface
    vec3 emission;     // radiance of the front sides, W/(m^2 sr)
};

// The surface of covered voxel v, which holds `record`.
VoxelSurface voxel_surface(ivec3 v, uint record) {
    VoxelSurface s;
    vec4 emission = unpack_value(voxel_emission[record]);
    s.albedo = unpack_value(voxel_albedo[record]).rgb;
    s.mean_normal = unpack_value(voxel_normal[record]).xyz;
    s.emission = emission.rgb;
    float length_n = length(s.mean_normal);
    // Surface point = centre + n * mean(dot(p_i - centre, n_i)): the centre projected onto a plane.
    s.position = voxel_center(v) + (length_n > 0.0 ? s.mean_normal / length_n * emission.a * voxel_extent(v) : vec3(0.0));
    return s;
}
