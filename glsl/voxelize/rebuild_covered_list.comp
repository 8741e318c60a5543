#version 450 core
// After a resolve, over the previous covered list: voxels still covered go on to the new list;
// voxels left empty get zero radiance (level 0 of the face views and the base radiance), so
// every empty voxel stays zero without touching the whole grid.
#include "lib/voxel.glsl"
#include "lib/list_append.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = TEX_VOXEL_ALBEDO) uniform sampler3D voxel_albedo;
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
layout(binding = IMG_BASE_OUT, rgba16f) uniform writeonly image3D base_out;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_COVERED_NEXT) buffer NextCovered { uint next_count; uint next_covered[]; };

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    uint entry = covered[gl_GlobalInvocationID.x];
    ivec3 v = unpack_voxel(entry);
    if (texelFetch(voxel_albedo, v, 0).a > 0.0) {
        APPEND(next_count, next_covered, entry);
        return;
    }
    imageStore(base_out, v, vec4(0.0));
    for (int f = 0; f < VOXEL_FACES; ++f) imageStore(faces_out, face_texel(v, f, voxel_grid), vec4(0.0));
}
