#version 450 core
// A cone emission volume made for a grid that already holds voxels (the first surface of the
// scene to emit): every covered voxel's emission (rgb) and coverage (a = 1), as the resolve
// writes them (voxelize/resolve_sums.comp).
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_CONE_EMISSION_OUT, rgba16f) uniform writeonly image3D cone_emission_out;
#include "lib/covered_voxels.glsl"

void main() {
    uint record = gl_GlobalInvocationID.x;
    ivec3 v;
    if (!covered_voxel(record, v)) return;
    imageStore(cone_emission_out, v, vec4(unpack_value(voxel_emission[record]).rgb, 1.0));
}
