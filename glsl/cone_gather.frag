#version 450 core
// Diffuse gather at half resolution: the lecture's 6 cones from the surface at the first pixel
// of each 2x2 block (rgb: sum_j w_j Lv(p, w_j), a: sum_j w_j alpha_j within gather_distance).
// cone_trace.frag upsamples it edge-aware; diffuse light varies slowly, so a quarter of the
// cones gives almost the same image.
#include "lib/gbuffer.glsl"
#include "lib/cone.glsl"

uniform float gather_distance;  // how far the cones look: the AO distance, or everywhere
layout(location = 0) out vec4 out_gathered;

void main() {
    ivec2 pixel = min(2 * ivec2(gl_FragCoord.xy), textureSize(gbuffer_position, 0) - 1);
    Surface s = read_gbuffer(pixel);
    out_gathered = s.covered ? trace_diffuse(s.position, s.normal, gather_distance) : vec4(0.0);
}
