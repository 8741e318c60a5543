#version 450 core
// Closes the bounce series: once the increments of successive bounces shrink by a steady
// ratio r, the remaining bounces add (L_k - L_{k-1}) r / (1 - r) (geometric series), so
//   L_inf = L_k + (L_k - L_{k-1}) * gain,  gain = r / (1 - r) per colour channel.
// Written over the older set, whose values are read first, for every covered voxel (empty
// ones are zero in both sets).
#include "engine_constants.glsl"
#include "lib/voxel.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = TEX_VOXEL_DIRECTIONAL) uniform sampler3D latest[VOXEL_FACES];
layout(binding = IMG_OUT_DIRECTIONAL, rgba16f) uniform image3D older[VOXEL_FACES];
layout(std430, binding = SSBO_OCCUPIED) readonly buffer OccupiedVoxels { uint occupied_count; uint occupied[]; };
uniform vec3 gain;

void main() {
    if (gl_GlobalInvocationID.x >= occupied_count) return;
    ivec3 v = unpack_voxel(occupied[gl_GlobalInvocationID.x]);
    for (int f = 0; f < VOXEL_FACES; ++f) {
        vec4 current = texelFetch(latest[f], v, 0);
        vec4 previous = imageLoad(older[f], v);
        imageStore(older[f], v, vec4(current.rgb + (current.rgb - previous.rgb) * gain, current.a));
    }
}
