#version 450 core
// Zeroes a volume of `views` stacks of the levels (the face views: VOXEL_FACES; the emission
// volume: 1) at one mip level over the cells that hold the entries of a list segment, where
// they lie in the levels of `cleared_levels` (bit k: level k): that level's cells of the
// previous geometry (before a full voxelization, or of a level about to scroll), or those of
// the voxels a voxelization touched (`voxel_entries`), so cells no surface
// covers any more read empty, and the cells whose surfaces changed read empty until the face
// views' mipmap builds them again (faces/mipmap_face_views.comp writes only faces with coverage).
#include "lib/segment_cells.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
uniform int views;
uniform uint cleared_levels;

void main() {
    if (gl_GlobalInvocationID.x >= segment_count()) return;
    int level = image_level(imageSize(faces_out));  // the level zeroed (1 up)
    ivec3 cell = segment_cell(gl_GlobalInvocationID.x, level);
    if (!in_level_mask(cleared_levels, cell << level)) return;
    for (int f = 0; f < views; ++f) imageStore(faces_out, face_texel(cell, f, voxel_grid >> level), vec4(0.0));
}
