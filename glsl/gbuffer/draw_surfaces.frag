#version 450 core
// G-buffer: position, shading normal + roughness, albedo + metalness, emission + dielectric F0,
// from the material's factors and textures (the normal map where NORMAL_MAP is defined);
// alpha-tested materials are cut out; where MOTION is defined, the point's position at the frame
// before.
#include "lib/material.glsl"

in vec3 world_position;
in vec3 world_normal;
flat in uint material;
#ifdef NORMAL_MAP
in vec4 world_tangent;
#endif
#ifdef VERTEX_EXTRAS
in vec3 vertex_color;
in vec4 map_coordinates01;
in vec4 map_coordinates23;
#else
in vec2 texcoord;
const vec3 vertex_color = vec3(1.0);
#endif
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;
layout(location = 3) out vec4 out_emission;
#ifdef MOTION
in vec3 previous_position;
layout(location = 4) out vec4 out_previous;
#endif

void main() {
#ifdef VERTEX_EXTRAS
    MapCoordinates coordinates = MapCoordinates(map_coordinates01, map_coordinates23);
#else
    MapCoordinates coordinates = same_coordinates(texcoord);
#endif
    MaterialSample m = sample_material(material, coordinates, vertex_color);
    if (cut_out(m)) discard;
    // Surfaces are one-sided emitters; a double-sided one reflects on the side we see.
    vec3 n = normalize(world_normal) * (gl_FrontFacing ? 1.0 : -1.0);
    out_position = vec4(world_position, 1.0);
#ifdef NORMAL_MAP
    n = shading_normal(material, n, world_tangent, coordinates);
#endif
    out_normal = vec4(n, m.roughness);
    out_albedo = vec4(m.albedo, m.metalness);
    out_emission = vec4(gl_FrontFacing ? m.emission : vec3(0.0), m.dielectric_f0);
#ifdef MOTION
    out_previous = vec4(previous_position, 1.0);
#endif
}
