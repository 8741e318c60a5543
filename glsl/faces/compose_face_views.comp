#version 450 core
// The radiance cones read at level 0, over a segment of a voxel list (the covered list: every
// voxel; the class list: in progressive frames one interleave class; or the voxels a
// voxelization touched, of which those no surface covers any more hold no record): the light each voxel's surface
// reflects, its base radiance less its emission plus the light it gathered,
// L = L_base - L_e + rho sum_j w_j L_in(p, w_j) (rho: its reflectance), into its record. Cones
// see it in the six one-sided face views premultiplied by how much of the voxel's surface faces
// each way (lib/cone.glsl faces_at_level_zero); faces/mipmap_face_views.comp builds the
// coarser levels from it. Emitted light reaches the surfaces as direct light
// (lib/emitters.glsl) and the specular cones from the emission volume.
#include "lib/voxel_surface.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_BASE) readonly buffer VoxelBase { uvec2 voxel_base[]; };
layout(std430, binding = SSBO_VOXEL_GATHERED) readonly buffer VoxelGathered { uvec2 voxel_gathered[]; };
layout(std430, binding = SSBO_VOXEL_REFLECTED) writeonly buffer VoxelReflected { uvec2 reflected_out[]; };
#include "lib/voxel_list.glsl"
uniform bool include_gathered;  // false before the first bounce
uniform uint composed_levels;   // bit k: level k's voxels are composed, the others keep theirs

void main() {
    ivec3 v;
    if (!segment_voxel(gl_GlobalInvocationID.x, v) || !in_level_mask(composed_levels, v)) return;
    uint record = voxel_record(v);
    if (record == NO_RECORD) return;
    int sides = sides_of(unpack_value(voxel_normal[side_value(record, 0)]));
    for (int side = 0; side < sides; ++side) {
        uint at = side_value(record, side);
        vec3 radiance = max(unpack_value(voxel_base[at]).rgb - unpack_value(voxel_emission[at]).rgb, vec3(0.0));
        if (include_gathered) radiance += unpack_value(voxel_albedo[at]).rgb * unpack_value(voxel_gathered[at]).rgb;
        reflected_out[at] = pack_value(vec4(radiance, 1.0));
    }
}
