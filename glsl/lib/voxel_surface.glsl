// The resolved surface of each voxel (written by voxelize/resolve_sums.comp): reflectance, mean
// normal, emission, and the point on the surface nearest the voxel centre.
#include "lib/voxel.glsl"

layout(binding = TEX_VOXEL_ALBEDO) uniform sampler3D voxel_albedo;     // rgb, a = 1 where covered
layout(binding = TEX_VOXEL_NORMAL) uniform sampler3D voxel_normal;     // xyz mean normal, w = 1 where covered
layout(binding = TEX_VOXEL_EMISSION) uniform sampler3D voxel_emission; // rgb, a = surface offset in voxels
// The emitters' shadowed irradiance at each voxel's surface (rgb) and the fraction of their
// unshadowed light that arrives (a), where voxel_emitters (emitter_light/light_voxels.comp).
layout(binding = TEX_VOXEL_EMITTER_IRRADIANCE) uniform sampler3D voxel_emitter_irradiance;
// The environment's irradiance at each voxel's surface through the voxels (rgb), where
// voxel_sky (sky_light/trace_sky_cones.comp).
layout(binding = TEX_VOXEL_SKY_IRRADIANCE) uniform sampler3D voxel_sky_irradiance;

struct VoxelSurface {
    bool covered;
    vec3 albedo;       // reflectance (lib/brdf.glsl layered_albedo), averaged over the voxel's fragments
    vec3 mean_normal;  // mean of the fragments' unit normals: its length is their coherence
    vec3 position;     // the voxel centre moved along the normal onto the (mean) surface
    vec3 emission;     // radiance of the front sides, W/(m^2 sr)
};

VoxelSurface voxel_surface(ivec3 v) {
    VoxelSurface s;
    vec4 albedo = texelFetch(voxel_albedo, v, 0);
    vec4 emission = texelFetch(voxel_emission, v, 0);
    s.covered = albedo.a > 0.0;
    s.albedo = albedo.rgb;
    s.mean_normal = texelFetch(voxel_normal, v, 0).xyz;
    s.emission = emission.rgb;
    float length_n = length(s.mean_normal);
    // Surface point = centre + n * mean(dot(p_i - centre, n_i)): the centre projected onto a plane.
    s.position = voxel_center(v) + (length_n > 0.0 ? s.mean_normal / length_n * emission.a * voxel_size : vec3(0.0));
    return s;
}
