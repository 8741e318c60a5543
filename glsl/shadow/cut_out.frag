#version 450 core
// Shadow map of alpha-tested materials: light goes through where they are cut out (the
// rasterizer writes gl_FragCoord.z into the atlas). Opaque materials are drawn without a
// fragment shader (engine/passes/shadow.py).
#include "lib/material.glsl"

in vec2 texcoord;
in vec2 texcoord1;

void main() {
    if (cut_out(sample_material(texcoord, texcoord1, vec3(1.0)).alpha)) discard;
}
