#version 450 core
// Shadow maps: depth of the scene seen from the light views of the atlas, every view of the list
// in one draw (lib/draws.glsl), each instance in its view's tile. Where the driver lets a vertex
// shader choose the viewport (VIEWPORT_INDEX: GL_ARB_shader_viewport_layer_array), a view's
// viewport is its tile; elsewhere the viewport is the whole atlas, and an instance is clipped to
// its view's frustum sides, then its x and y placed in the tile.
#ifdef VIEWPORT_INDEX
#extension GL_ARB_shader_viewport_layer_array : require
#endif
#include "lib/draws.glsl"
#include "lib/draw_views.glsl"
#include "lib/material.glsl"

in uint in_instance;  // the draw and view of this instance (lib/draws.glsl)
in vec3 in_position;
in vec2 in_texcoord;
flat out uint material;
#ifdef VERTEX_EXTRAS
in vec2 in_texcoord1;
out vec4 map_coordinates01;  // MapCoordinates (lib/material.glsl)
out vec4 map_coordinates23;
#else
out vec2 texcoord;
#endif
#ifndef VIEWPORT_INDEX
out gl_PerVertex {
    vec4 gl_Position;
    float gl_ClipDistance[4];  // >= 0 inside the view's four frustum sides
};
#endif

void main() {
    uint view = value_view(in_instance);
    vec4 clip = views[view].view_projection * vec4(value_world(in_instance) * vec4(in_position, 1.0), 1.0);
#ifdef VIEWPORT_INDEX
    gl_ViewportIndex = int(view);
    gl_Position = clip;
#else
    gl_ClipDistance[0] = clip.w - clip.x;
    gl_ClipDistance[1] = clip.w + clip.x;
    gl_ClipDistance[2] = clip.w - clip.y;
    gl_ClipDistance[3] = clip.w + clip.y;
    gl_Position = vec4(clip.xy * views[view].tile.zw + views[view].tile.xy * clip.w, clip.zw);  // NDC x' = x scale + offset
#endif
    material = value_material(in_instance);
#ifdef VERTEX_EXTRAS
    MapCoordinates coordinates = material_coordinates(material, in_texcoord, in_texcoord1);
    map_coordinates01 = coordinates.maps01;
    map_coordinates23 = coordinates.maps23;
#else
    texcoord = in_texcoord;
#endif
}
