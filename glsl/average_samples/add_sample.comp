#version 450 core
// One jittered sample of the image added to the running mean of a frame's samples (a box pixel
// filter: engine/passes/average_samples.py): m_k = m_(k-1) + (x_k - m_(k-1)) / k.
#include "engine_constants.glsl"

layout(local_size_x = SCREEN_GROUP, local_size_y = SCREEN_GROUP) in;
layout(binding = TEX_HDR_INPUT) uniform sampler2D sample_image;
layout(binding = IMG_AVERAGE_OUT, rgba32f) uniform image2D average;
uniform float sample_weight;  // 1 / k for the k-th sample

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(average)))) return;
    vec4 value = texelFetch(sample_image, pixel, 0);
    imageStore(average, pixel, sample_weight >= 1.0 ? value : mix(imageLoad(average, pixel), value, sample_weight));
}
