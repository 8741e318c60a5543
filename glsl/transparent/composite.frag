#version 450 core
// The blended surfaces over the opaque image (transparent/shade_blended.frag's sums and
// coverage c = 1 - prod (1 - a)):
//   L = (sum w a C / sum w a) c + L_opaque (1 - c)
// exact for one layer: a pane of alpha a shows a of its own light and 1 - a of what lies behind.
#include "engine_constants.glsl"

layout(binding = TEX_HDR_INPUT) uniform sampler2D opaque_image;
layout(binding = TEX_BLEND_SUMS) uniform sampler2D blend_sums;
layout(binding = TEX_BLEND_COVERAGE) uniform sampler2D blend_coverage;
layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 opaque = texelFetch(opaque_image, pixel, 0);
    float coverage = texelFetch(blend_coverage, pixel, 0).r;
    if (coverage <= 0.0) { out_radiance = opaque; return; }
    vec4 sums = texelFetch(blend_sums, pixel, 0);
    vec3 blended = sums.rgb / max(sums.a, 1e-6);
    out_radiance = vec4(blended * coverage + opaque.rgb * (1.0 - coverage), max(opaque.a, coverage));
}
