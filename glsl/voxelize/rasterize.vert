#version 450 core
// Voxelization, vertex stage: world-space triangle corners, normals and texture coordinates
// (vertex colours and each map's coordinates where VERTEX_EXTRAS: lib/material.glsl), and the
// job its instance draws into (lib/draw_views.glsl: a level and its voxels to write). An
// instance of a held draw (a moved draw as the voxels hold it, which the mark stage draws) is
// marked without its material: what it covered is rebuilt whether or not it was cut out.
#define HELD_DRAWS
#include "lib/draws.glsl"
#include "lib/draw_views.glsl"
#include "lib/material.glsl"

in uint in_instance;  // the draw and view of this instance (lib/draws.glsl)
in vec3 in_position;
in vec3 in_normal;
in vec2 in_texcoord;
out vec3 vs_position;
out vec3 vs_normal;
flat out uint vs_material;     // NO_MATERIAL for a held draw
flat out ivec4 vs_voxels_min;  // the job's voxels [min, max) in its level's coordinates; w: the level
flat out ivec3 vs_voxels_max;
#ifdef VERTEX_EXTRAS
in vec3 in_color;
in vec2 in_texcoord1;
out vec3 vs_color;
out vec4 vs_map_coordinates01;  // MapCoordinates (lib/material.glsl)
out vec4 vs_map_coordinates23;
#else
out vec2 vs_texcoord;
#endif

void main() {
    mat4x3 world = value_world(in_instance);
    DrawView job = views[value_view(in_instance)];
    vs_position = world * vec4(in_position, 1.0);
    vs_normal = normal_transform(mat3(world)) * in_normal;
    vs_material = value_held(in_instance) ? NO_MATERIAL : value_material(in_instance);
    vs_voxels_min = job.voxels_min;
    vs_voxels_max = job.voxels_max.xyz;
#ifdef VERTEX_EXTRAS
    vs_color = in_color;
    MapCoordinates coordinates = vs_material == NO_MATERIAL ? same_coordinates(in_texcoord)
                                                           : material_coordinates(vs_material, in_texcoord, in_texcoord1);
    vs_map_coordinates01 = coordinates.maps01;
    vs_map_coordinates23 = coordinates.maps23;
#else
    vs_texcoord = in_texcoord;
#endif
}
