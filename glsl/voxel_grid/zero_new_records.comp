#version 450 core
// After a voxelization, over the voxels its resolve listed as newly covered: the light at
// their records starts at zero, as at an empty voxel (the records were another voxel's
// before), in the arrays the passes own: base radiance, both gathers, the reflected light,
// and where the scene has them the emitters' and the sky's light (VoxelGrid.zero_new_records).
#include "lib/voxel_records.glsl"
#include "lib/list_append.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_NEWLY_COVERED) readonly buffer NewlyCovered { uint new_count; uint newly_covered[]; };
layout(std430, binding = SSBO_VOXEL_BASE) writeonly buffer VoxelBase { uvec2 base_out[]; };
layout(std430, binding = SSBO_VOXEL_GATHERED) writeonly buffer VoxelGathered { uvec2 gathered_out[]; };
layout(std430, binding = SSBO_GATHERED_OUT) writeonly buffer VoxelGatheredPrevious { uvec2 previous_gathered_out[]; };
layout(std430, binding = SSBO_VOXEL_REFLECTED) writeonly buffer VoxelReflected { uvec2 reflected_out[]; };
layout(std430, binding = SSBO_VOXEL_EMITTER_IRRADIANCE) writeonly buffer VoxelEmitterIrradiance { uvec2 emitter_irradiance_out[]; };
layout(std430, binding = SSBO_VOXEL_SKY_IRRADIANCE) writeonly buffer VoxelSkyIrradiance { uvec2 sky_irradiance_out[]; };
layout(std430, binding = SSBO_VOXEL_TRACED_SKY_IRRADIANCE) writeonly buffer VoxelTracedSky { uvec2 traced_sky_out[]; };

void main() {
    if (gl_GlobalInvocationID.x >= LISTED(new_count, newly_covered)) return;
    uint record = voxel_record(unpack_voxel(newly_covered[gl_GlobalInvocationID.x]));
    for (int side = 0; side < VOXEL_SIDES; ++side) {
        uint at = side_value(record, side);
        // One store a statement: a chained assignment reads the stores' value back from the
        // writeonly buffers, which NVIDIA's compiler refuses.
        base_out[at] = uvec2(0u);
        gathered_out[at] = uvec2(0u);
        previous_gathered_out[at] = uvec2(0u);
        reflected_out[at] = uvec2(0u);
        if (voxel_emitters) emitter_irradiance_out[at] = uvec2(0u);
        if (voxel_sky) {
            traced_sky_out[at] = uvec2(0u);
            sky_irradiance_out[at] = uvec2(0u);
        }
    }
}
