#version 450 core
// Copies one mip level of a voxel volume into a storage buffer, for inspection from Python.
#include "engine_constants.glsl"

layout(local_size_x = VOLUME_GROUP, local_size_y = VOLUME_GROUP, local_size_z = VOLUME_GROUP) in;
layout(binding = TEX_VOXEL_INSPECT) uniform sampler3D volume;
uniform int level;
layout(std430, binding = SSBO_READBACK) writeonly buffer Texels { vec4 texels[]; };

void main() {
    ivec3 size = textureSize(volume, level);
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, size))) return;
    texels[(v.z * size.y + v.y) * size.x + v.x] = texelFetch(volume, v, level);
}
