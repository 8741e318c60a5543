#version 450 core
// G-buffer geometry: world position, normal, texture coordinates and, for a material with a
// normal map (NORMAL_MAP defined), tangent of every visible surface; for a mesh with vertex
// colours or a second texture coordinate set, or a material that transforms its texture
// coordinates (VERTEX_EXTRAS), those. Without them they are not passed on: on llvmpipe every
// output of this stage costs each triangle's setup time. Each instance is a draw of the list
// (lib/draws.glsl).
#include "lib/camera.glsl"
#include "lib/draws.glsl"
#include "lib/material.glsl"

in uint in_instance;  // the draw and view of this instance (lib/draws.glsl)
in vec3 in_position;
in vec3 in_normal;
in vec2 in_texcoord;
out vec3 world_position;
out vec3 world_normal;
flat out uint material;
#ifdef NORMAL_MAP
in vec4 in_tangent;
out vec4 world_tangent;
#endif
#ifdef VERTEX_EXTRAS
in vec3 in_color;
in vec2 in_texcoord1;
out vec3 vertex_color;
out vec4 map_coordinates01;  // MapCoordinates (lib/material.glsl)
out vec4 map_coordinates23;
#else
out vec2 texcoord;
#endif

void main() {
    mat4x3 world = value_world(in_instance);
    uint draw_material = value_material(in_instance);
    world_position = world * vec4(in_position, 1.0);
    world_normal = normal_transform(mat3(world)) * in_normal;
#ifdef NORMAL_MAP
    world_tangent = vec4(mat3(world) * in_tangent.xyz, in_tangent.w);
#endif
#ifdef VERTEX_EXTRAS
    vertex_color = in_color;
    MapCoordinates coordinates = material_coordinates(draw_material, in_texcoord, in_texcoord1);
    map_coordinates01 = coordinates.maps01;
    map_coordinates23 = coordinates.maps23;
#else
    texcoord = in_texcoord;
#endif
    material = draw_material;
    gl_Position = camera.view_projection * vec4(world_position, 1.0);
}
