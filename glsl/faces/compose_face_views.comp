#version 450 core
// The radiance cones read, over a segment of a voxel list (the class list: every voxel, or in
// progressive frames one interleave class; or the voxels a voxelization touched, of which
// those no surface covers any more are left as the voxelization emptied them): the light each
// voxel's surface reflects, its base radiance less its emission plus the light it gathered,
// L = L_base - L_e + rho sum_j w_j L_in(p, w_j) (rho: its reflectance), into the six one-sided
// face views premultiplied by how much of the voxel's surface faces each way (coverage in a),
// level 0; faces/mipmap_face_views.comp builds the coarser levels. Only the faces the surface covers are
// written: the others are zero since the voxel was resolved (voxelize/resolve_sums.comp), which saves
// a third of the pass (most voxels of a wall face one way). Emitted light reaches the surfaces as
// direct light (lib/emitters.glsl) and the specular cones from the emission volume.
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_BASE) readonly buffer VoxelBase { uvec2 voxel_base[]; };
layout(std430, binding = SSBO_VOXEL_GATHERED) readonly buffer VoxelGathered { uvec2 voxel_gathered[]; };
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
#include "lib/voxel_list.glsl"
uniform bool include_gathered;  // false before the first bounce

void main() {
    if (gl_GlobalInvocationID.x >= segment_count()) return;
    ivec3 v = unpack_voxel(voxel_list[segment_first() + gl_GlobalInvocationID.x]);
    uint record = voxel_record(v);
    if (record == NO_RECORD) return;
    vec3 radiance = max(unpack_value(voxel_base[record]).rgb - unpack_value(voxel_emission[record]).rgb, vec3(0.0));
    vec3 mean_normal = unpack_value(voxel_normal[record]).xyz;
    if (include_gathered) radiance += unpack_value(voxel_albedo[record]).rgb * unpack_value(voxel_gathered[record]).rgb;
    for (int f = 0; f < VOXEL_FACES; ++f) {
        float coverage = face_coverage(mean_normal, f);
        if (coverage > 0.0) imageStore(faces_out, face_texel(v, f, voxel_grid), vec4(radiance * coverage, coverage));
    }
}
