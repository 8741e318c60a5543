#version 450 core
// After a resolve, over the previous covered list: voxels still covered (they hold a record)
// go on to the new list; voxels left empty get zero radiance at level 0 of the face views, so
// every empty voxel stays zero without touching the whole grid.
#include "lib/voxel_records.glsl"
#include "lib/list_append.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
#include "lib/covered_voxels.glsl"
layout(std430, binding = SSBO_COVERED_NEXT) buffer NextCovered { uint next_count; uint next_covered[]; };

void main() {
    if (gl_GlobalInvocationID.x >= covered_count) return;
    uint entry = covered[gl_GlobalInvocationID.x];
    ivec3 v = unpack_voxel(entry);
    if (voxel_record(v) != NO_RECORD) {
        APPEND(next_count, next_covered, entry);
        return;
    }
    for (int f = 0; f < VOXEL_FACES; ++f) imageStore(faces_out, face_texel(v, f, voxel_grid), vec4(0.0));
}
