#version 450 core
// Closes the bounce series: once the increments of successive bounces shrink by a steady
// ratio r, the remaining bounces add (G_k - G_{k-1}) r / (1 - r) (geometric series), so
//   G_inf = G_k + (G_k - G_{k-1}) * gain,  gain = r / (1 - r) per colour channel,
// written over the older gather, for every covered voxel.
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = TEX_VOXEL_GATHERED) uniform sampler3D latest;
layout(binding = IMG_GATHERED_OUT, rgba16f) uniform image3D older;
#include "lib/covered_voxels.glsl"
uniform vec3 gain;

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    ivec3 v = unpack_voxel(covered[gl_GlobalInvocationID.x]);
    vec4 current = texelFetch(latest, v, 0);
    vec3 previous = imageLoad(older, v).rgb;
    imageStore(older, v, vec4(current.rgb + (current.rgb - previous) * gain, current.a));
}
