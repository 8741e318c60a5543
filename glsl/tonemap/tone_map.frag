#version 450 core
// HDR radiance -> display: exposure, tone curve (none, Reinhard, ACES), sRGB encoding.
#include "engine_constants.glsl"

layout(binding = TEX_HDR_INPUT) uniform sampler2D hdr_input;
uniform float exposure;
uniform int tonemap;
uniform bool encode_srgb;
layout(location = 0) out vec4 out_color;

// Narkowicz's fit of the ACES filmic reference rendering transform.
vec3 aces_film(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// sRGB opto-electronic transfer function (IEC 61966-2-1).
vec3 srgb_encode(vec3 c) {
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main() {
    vec3 c = max(texelFetch(hdr_input, ivec2(gl_FragCoord.xy), 0).rgb, 0.0) * exposure;
    if (tonemap == TONEMAP_REINHARD) c = c / (1.0 + c);   // Reinhard: L / (1 + L)
    else if (tonemap == TONEMAP_ACES) c = aces_film(min(c, 1e4));  // the fit is 1 from there on; its products overflow later
    c = clamp(c, 0.0, 1.0);
    out_color = vec4(encode_srgb ? srgb_encode(c) : c, 1.0);
}
