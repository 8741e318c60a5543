// The pixels that trace cones of their own (cone_trace.frag lists them, cone_pixels.comp
// traces them): the dispatch size of cone_pixels.comp, the count, and per pixel its packed
// coordinates and which cones it needs.
#include "engine_constants.glsl"

#define PIXEL_DIFFUSE_CONES 1u
#define PIXEL_SPECULAR_CONE 2u

layout(std430, binding = SSBO_CONE_PIXELS) buffer ConePixels { uvec3 pixel_groups; uint pixel_count; uvec2 pixels[]; };
