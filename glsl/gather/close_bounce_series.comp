#version 450 core
// Closes the bounce series: once the increments of successive bounces shrink by a steady
// ratio r, the remaining bounces add (G_k - G_{k-1}) r / (1 - r) (geometric series), so
//   G_inf = G_k + (G_k - G_{k-1}) * gain,  gain = r / (1 - r) per colour channel,
// written over the older gather, for every covered voxel.
#include "lib/voxel_records.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_GATHERED) readonly buffer Latest { uvec2 latest[]; };
layout(std430, binding = SSBO_GATHERED_OUT) buffer Older { uvec2 older[]; };
#include "lib/covered_voxels.glsl"
uniform vec3 gain;

void main() {
    uint record = gl_GlobalInvocationID.x;
    ivec3 v;
    if (!covered_voxel(record, v)) return;
    for (int side = 0; side < VOXEL_SIDES; ++side) {
        uint at = side_value(record, side);
        vec4 current = unpack_value(latest[at]);
        vec3 previous = unpack_value(older[at]).rgb;
        older[at] = pack_value(vec4(current.rgb + (current.rgb - previous) * gain, current.a));
    }
}
