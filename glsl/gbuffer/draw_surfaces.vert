#version 450 core
// G-buffer geometry: world position, normal, texture coordinates and, for a material with a
// normal map (NORMAL_MAP defined), tangent of every visible surface; for a mesh with vertex
// colours or a second texture coordinate set, or a material that transforms its texture
// coordinates (VERTEX_EXTRAS), those. Without them they are not passed on: on llvmpipe every
// output of this stage costs each triangle's setup time. Where MOTION is defined (temporal
// anti-aliasing), also where the point was at the frame before: the draw's motion since then
// (SSBO_DRAW_MOTIONS) applied to the vertex as it was (a posed draw's position before its
// latest pose, engine/passes/pose.py). Each instance is a draw of the list (lib/draws.glsl).
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
#ifdef MOTION
layout(std430, binding = SSBO_DRAW_MOTIONS) readonly buffer DrawMotions { mat4 draw_motions[]; };
layout(std430, binding = SSBO_POSE_PREVIOUS) readonly buffer PosePrevious { vec4 previous_positions[]; };
out vec3 previous_position;
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
#ifdef MOTION
    uint draw = in_instance & DRAW_INDEX_MASK;
    // gl_VertexID counts from the pool's first vertex (the draw's base vertex is added).
    vec3 local_before = value_posed(in_instance) ? previous_positions[gl_VertexID].xyz : in_position;
    previous_position = (draw_motions[draw] * vec4(world * vec4(local_before, 1.0), 1.0)).xyz;
#endif
    gl_Position = camera.view_projection * vec4(world_position, 1.0);
}
