#version 450 core
// Scrolls a clipmap level whose cube moved by whole voxels of its own, `level_shift` of them:
// each voxel it holds still keeps its record, and so its surface and light, at its coordinates
// in the moved cube, v - level_shift; the voxels the cube left behind give their records back
// to the pool and the covered list reads NO_VOXEL at them. Two dispatches over the covered
// list: `lifting` clears the level's words of the record index, then every record of the
// level is placed at its voxel's new word (distinct voxels move to distinct words).
#include "lib/covered_voxels.glsl"
#include "lib/voxel_records.glsl"
#include "lib/record_pool.glsl"

layout(local_size_x = LIST_GROUP) in;
uniform int scrolled_level;
uniform ivec3 level_shift;
uniform bool lifting;

void main() {
    uint record = gl_GlobalInvocationID.x;
    ivec3 v;
    if (!covered_voxel(record, v) || voxel_level(v) != scrolled_level) return;
    if (lifting) {
        voxel_records[voxel_index(v)] = 0u;
        return;
    }
    ivec3 local = ivec3(v.xy, v.z - scrolled_level * voxel_grid) - level_shift;
    if (all(greaterThanEqual(local, ivec3(0))) && all(lessThan(local, ivec3(voxel_grid)))) {
        ivec3 moved = level_voxel(local, scrolled_level);
        voxel_records[voxel_index(moved)] = record + 1u;
        covered[record] = pack_voxel(moved);
    } else {
        give_back_record(record);
        covered[record] = NO_VOXEL;
    }
}
