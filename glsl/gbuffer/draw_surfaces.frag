#version 450 core
// G-buffer: position, shading normal + roughness, albedo + metalness, emission + dielectric F0,
// from the material's factors and textures (the normal map where NORMAL_MAP is defined);
// alpha-tested materials are cut out.
#include "lib/material.glsl"

in vec3 world_position;
in vec3 world_normal;
in vec2 texcoord;
#ifdef NORMAL_MAP
in vec4 world_tangent;
#endif
#ifdef VERTEX_EXTRAS
in vec3 vertex_color;
in vec2 texcoord1;
#else
const vec3 vertex_color = vec3(1.0);
const vec2 texcoord1 = vec2(0.0);
#endif
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;
layout(location = 3) out vec4 out_emission;

void main() {
    MaterialSample m = sample_material(texcoord, texcoord1, vertex_color);
    if (cut_out(m.alpha)) discard;
    // Surfaces are one-sided emitters; a double-sided one reflects on the side we see.
    vec3 n = normalize(world_normal) * (gl_FrontFacing ? 1.0 : -1.0);
    out_position = vec4(world_position, 1.0);
#ifdef NORMAL_MAP
    n = shading_normal(n, world_tangent, texcoord, texcoord1);
#endif
    out_normal = vec4(n, m.roughness);
    out_albedo = vec4(m.albedo, m.metalness);
    out_emission = vec4(gl_FrontFacing ? m.emission : vec3(0.0), dielectric_f0);
}
