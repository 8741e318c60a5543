#version 450 core
// One mip level of the face views, over the cells that hold the entries of a list segment: the
// level's covered cells (all of them, or at level 1 those of one interleave class:
// gather/sort_class_cells.comp), or the voxels a voxelization touched (`voxel_entries`): each
// cell is the mean of its 8 children one level finer (a box filter, as glGenerateMipmap), so a
// level-m cell holds the mean premultiplied radiance and coverage of the 2^m voxels along each
// side. At level 1 the children are voxels, seen as cones see level 0 (lib/cone.glsl
// voxel_face): their reflected light times the coverage of each face. Cells no surface covers
// are zero and stay zero (voxel_grid/clear_cells.comp, run by FaceViewsPass).
#include "lib/segment_cells.glsl"
#include "lib/cone.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_FACES_OUT, rgba16f) uniform writeonly image3D faces_out;
uniform uint mipmapped_levels;  // bit k: grid level k's cells are made again, the others keep theirs

void main() {
    if (gl_GlobalInvocationID.x >= segment_count()) return;
    int level = image_level(imageSize(faces_out));  // the level written (1 up)
    ivec3 cell = segment_cell(gl_GlobalInvocationID.x, level);
    int side = voxel_grid >> level;
    if ((mipmapped_levels & (1u << (cell.z / side))) == 0u) return;
    vec4 mean[VOXEL_FACES];
    if (level == 1) {
        for (int f = 0; f < VOXEL_FACES; ++f) mean[f] = vec4(0.0);
        for (int child = 0; child < 8; ++child) {
            ivec3 v = 2 * cell + corner_offset(child);
            uint record = voxel_record(v);
            if (record == NO_RECORD) continue;
            // Each side in the faces it faces (the second where the voxel has two).
            vec4 side_0_normal = unpack_value(voxel_normal[side_value(record, 0)]);
            for (int side = 0; side < sides_of(side_0_normal); ++side) {
                vec4 mean_normal = side_normal(record, side, side_0_normal);  // w: its opacity
                vec3 reflected = unpack_value(voxel_reflected[side_value(record, side)]).rgb;
                FaceCoverage coverage = face_coverages(mean_normal.xyz);
                for (int f = 0; f < VOXEL_FACES; ++f) mean[f] += 0.125 * voxel_face(reflected, abs(mean_normal.w) * face_coverage(coverage, f));
            }
        }
    } else {
        // The corner the 8 children share, in the finer level's texture coordinates: a
        // trilinear lookup there weighs each child 1/8, one fetch where 8 would do the same.
        vec3 finer_size = vec3(2 * side, 2 * side, 2 * side * VOXEL_FACES * voxel_levels);
        for (int f = 0; f < VOXEL_FACES; ++f) {
            vec3 corner = vec3(face_texel(2 * cell + 1, f, 2 * side));
            mean[f] = textureLod(voxel_faces, corner / finer_size, float(level - 2));  // it holds levels 1 and up
        }
    }
    // A face no surface of the cell covers is zero, as it has been since the cell was cleared:
    // not written (most cells of a wall face one way).
    for (int f = 0; f < VOXEL_FACES; ++f)
        if (mean[f].a > 0.0) imageStore(faces_out, face_texel(cell, f, side), mean[f]);
}
