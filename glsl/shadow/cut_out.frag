#version 450 core
// Shadow map of alpha-tested materials: light goes through where they are cut out, and through
// 1 - alpha of a blended one's texels (the rasterizer writes gl_FragCoord.z into the atlas). Opaque materials are drawn without a
// fragment shader (engine/passes/shadow.py).
#include "lib/material.glsl"

flat in uint material;
#ifdef VERTEX_EXTRAS
in vec4 map_coordinates01;
in vec4 map_coordinates23;
#else
in vec2 texcoord;
#endif

void main() {
#ifdef VERTEX_EXTRAS
    MapCoordinates coordinates = MapCoordinates(map_coordinates01, map_coordinates23);
#else
    MapCoordinates coordinates = same_coordinates(texcoord);
#endif
    MaterialSample m = sample_material(material, coordinates, vec3(1.0));
    if (cut_out(m) || dissolved(m, vec3(gl_FragCoord.xy, 0.0))) discard;
}
