#version 450 core
// An array of values (per record and side: engine/voxels/records.py) into an n^3 volume, over the
// covered voxels, for inspection: the voxel views and Renderer.voxels show each voxel's side 0,
// the orientation most of its surfaces have (the volume is zero before, so empty voxels read zero).
#include "lib/voxel_records.glsl"

layout(local_size_x = LIST_GROUP) in;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_INSPECT_VALUES) readonly buffer Values { uvec2 values[]; };
layout(binding = IMG_INSPECT_OUT, rgba16f) uniform writeonly image3D inspect_out;

void main() {
    uint record = gl_GlobalInvocationID.x;
    ivec3 v;
    if (covered_voxel(record, v)) imageStore(inspect_out, v, unpack_value(values[side_value(record, 0)]));
}
