// The light arriving at each covered voxel's surface from the emitters and the sky, per record
// (lib/voxel_records.glsl).
#include "lib/voxel_records.glsl"

// The emitters' shadowed irradiance at each voxel's surface (rgb) and the fraction of their
// unshadowed light that arrives (a), where voxel_emitters (emitter_light/light_voxels.comp).
layout(std430, binding = SSBO_VOXEL_EMITTER_IRRADIANCE) readonly buffer VoxelEmitterIrradiance { uvec2 voxel_emitter_irradiance[]; };
// The environment's irradiance at each voxel's surface through the voxels (rgb), where
// voxel_sky (sky_light/filter_sky_light.comp).
layout(std430, binding = SSBO_VOXEL_SKY_IRRADIANCE) readonly buffer VoxelSkyIrradiance { uvec2 voxel_sky_irradiance[]; };
