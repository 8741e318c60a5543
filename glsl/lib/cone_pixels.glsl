// The pixels that need cones of their own, listed by cone_trace.frag in two lists, each with
// the group count of its indirect dispatch and its length: the cone pixels (cone_pixels.comp
// traces their diffuse cones and, at the anchors, even x and y, their specular cone), then the
// shared pixels between the anchors (cone_specular_shared.comp). Apart, so that the lanes of a
// group all trace, or all interpolate.
#include "engine_constants.glsl"

#define PIXEL_DIFFUSE_CONES 1u
#define PIXEL_SPECULAR_CONE 2u

layout(std430, binding = SSBO_CONE_PIXELS) buffer ConePixels { uvec3 pixel_groups; uint pixel_count; uvec2 pixels[]; };
layout(std430, binding = SSBO_SHARED_PIXELS) buffer SharedPixels { uvec3 shared_groups; uint shared_count; uint shared_pixels[]; };

uint pack_pixel(ivec2 pixel) {
    return uint(pixel.x) | (uint(pixel.y) << 16);
}

ivec2 unpack_pixel(uint code) {
    return ivec2(code & 0xffffu, code >> 16);
}
