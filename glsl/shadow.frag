#version 450 core
// Depth only (the rasterizer writes gl_FragCoord.z into the shadow atlas); alpha-tested
// materials let light through where they are cut out.
#include "lib/material.glsl"

in vec2 texcoord;

void main() {
    if (cut_out(sample_material(texcoord).alpha)) discard;
}
