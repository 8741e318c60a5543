#version 450 core
// The mean premultiplied radiance of each face view over the whole grid (its 1^3 level), for
// the bounce convergence test.
#include "engine_constants.glsl"

layout(local_size_x = 1) in;
layout(binding = TEX_VOXEL_FACES) uniform sampler3D voxel_faces;  // stacked: the 1^3 level is 1 x 1 x 6
layout(std430, binding = SSBO_READBACK) writeonly buffer Totals { vec4 totals[VOXEL_FACES]; };
uniform int top_level;

void main() {
    for (int f = 0; f < VOXEL_FACES; ++f) totals[f] = texelFetch(voxel_faces, ivec3(0, 0, f), top_level);
}
