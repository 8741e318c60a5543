#version 450 core
// The blended surfaces over the opaque image (transparent/shade_blended.frag's sums):
//   L = (sum w a C / sum w a) (1 - prod (1 - a)) + L_opaque prod (1 - a)
// exact for one layer: a pane of alpha a shows a of its own light and 1 - a of what lies behind.
#include "engine_constants.glsl"

layout(binding = TEX_HDR_INPUT) uniform sampler2D opaque_image;
layout(binding = TEX_BLEND_SUMS) uniform sampler2D blend_sums;
layout(binding = TEX_BLEND_REVEALAGE) uniform sampler2D blend_revealage;
layout(location = 0) out vec4 out_radiance;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 opaque = texelFetch(opaque_image, pixel, 0);
    float revealage = texelFetch(blend_revealage, pixel, 0).r;
    if (revealage >= 1.0) { out_radiance = opaque; return; }
    vec4 sums = texelFetch(blend_sums, pixel, 0);
    vec3 blended = sums.rgb / max(sums.a, 1e-6);
    out_radiance = vec4(blended * (1.0 - revealage) + opaque.rgb * revealage, max(opaque.a, 1.0 - revealage));
}
