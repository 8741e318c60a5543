#version 450 core
// The emission volume the specular cones read (grid.cone_emission: mip level 1 and coarser of
// the voxels' emission; the cones read no finer), its level 1 over the cells that hold the
// entries of a list segment: every covered cell (a volume made for a grid that already holds
// voxels) or the voxels a voxelization touched (`voxel_entries`). Each cell is the mean
// of its 8 voxels' emission (rgb) and coverage (a; 1 where covered), as a mip level of a volume
// of the voxels would hold; glGenerateMipmap builds the coarser levels.
#include "lib/voxel_surface.glsl"
#include "lib/segment_cells.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_CONE_EMISSION_OUT, rgba16f) uniform writeonly image3D cone_emission_out;

void main() {
    if (gl_GlobalInvocationID.x >= segment_count()) return;
    ivec3 cell = segment_cell(gl_GlobalInvocationID.x, 1);
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 8; ++k) {
        uint record = voxel_record(2 * cell + corner_offset(k));
        if (record != NO_RECORD)  // what both sides emit
            sum += vec4(unpack_value(voxel_emission[side_value(record, 0)]).rgb + unpack_value(voxel_emission[side_value(record, 1)]).rgb, 1.0);
    }
    imageStore(cone_emission_out, cell, sum / 8.0);
}
