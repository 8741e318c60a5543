// The pixels that need cones, in three lists, each with the group count of its indirect
// dispatch and its length, and each entry with the cones it needs. cone_trace/shade_pixels.frag
// lists the cone pixels (cone_trace/trace_listed_pixels.comp traces their cones: the anchors,
// even x and y, and the pixels whose specular cone is too narrow to share) and the shared
// pixels between the anchors (cone_trace/share_anchor_cones.comp takes the light of their
// cones from the anchors, and lists those no anchor stood for as unshared pixels, which trace
// their own). Apart, so that the lanes of a group all trace, or all interpolate.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_CONE_PIXELS) buffer ConePixels { uvec3 pixel_groups; uint pixel_count; uvec2 pixels[]; };
layout(std430, binding = SSBO_SHARED_PIXELS) buffer SharedPixels { uvec3 shared_groups; uint shared_count; uvec2 shared_pixels[]; };
layout(std430, binding = SSBO_UNSHARED_PIXELS) buffer UnsharedPixels { uvec3 unshared_groups; uint unshared_count; uvec2 unshared_pixels[]; };
// The image's terms (engine/frame/settings.py ImageTerms) the listed pixels' light belongs to: the
// diffuse cones' gather is weighed by the diffuse layer where include_diffuse and by a specular
// lobe as wide as the hemisphere where include_specular (lib/specular_cone.glsl
// hemisphere_reflectance); the specular cones count where include_specular.
uniform bool include_diffuse;
uniform bool include_specular;
// Per anchor: sum_j w_j Lv(p, w_j) of the diffuse cones it traced, a = 1 (a = 0: it traced none).
layout(binding = IMG_DIFFUSE_IN, rgba32f) uniform image2D diffuse_in;

// Append an entry (pack_pixel, cones) to the cone list or the shared list; each list's
// dispatch size grows by a group every LIST_GROUP pixels.
void list_cone_pixel(uvec2 entry) {
    uint k = atomicAdd(pixel_count, 1u);
    if (k % uint(LIST_GROUP) == 0u) atomicAdd(pixel_groups.x, 1u);
    pixels[k] = entry;
}

void list_shared_pixel(uvec2 entry) {
    uint k = atomicAdd(shared_count, 1u);
    if (k % uint(LIST_GROUP) == 0u) atomicAdd(shared_groups.x, 1u);
    shared_pixels[k] = entry;
}

void list_unshared_pixel(uvec2 entry) {
    uint k = atomicAdd(unshared_count, 1u);
    if (k % uint(LIST_GROUP) == 0u) atomicAdd(unshared_groups.x, 1u);
    unshared_pixels[k] = entry;
}

// The anchor pixels trace the cones the pixels between them share.
bool is_anchor(ivec2 pixel) {
    return all(equal(pixel % 2, ivec2(0)));
}

uint pack_pixel(ivec2 pixel) {
    return uint(pixel.x) | (uint(pixel.y) << 16);
}

ivec2 unpack_pixel(uint code) {
    return ivec2(code & 0xffffu, code >> 16);
}
