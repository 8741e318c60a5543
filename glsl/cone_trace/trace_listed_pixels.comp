#version 450 core
// The cones of the pixels cone_trace/shade_pixels.frag listed, added to the image:
//   diffuse:  c_d sum_j w_j Lv(p, w_j, a_j) (c_d: lib/brdf.glsl diffuse_layer_albedo), where
//             no voxel around p faces its way, at
//             the anchor pixels, whose gather is kept for the pixels between them
//             (cone_trace/share_anchor_cones.comp)
//   specular: A(w_o) Lv(p, w_s, a_s) at the anchor pixels (lib/specular_cone.glsl), whose
//             Lv is kept likewise, and at every pixel whose cone is too narrow to share
//   AO:       1 - sum_j w_j alpha_j of the diffuse cones within ao_distance, at every pixel
// Built twice: over the cone pixels cone_trace/shade_pixels.frag listed, and (TRACE_UNSHARED)
// over the pixels between anchors that no anchor stood for (cone_trace/share_anchor_cones.comp
// lists them). Dispatched indirectly with the group count the listing counted.
#include "lib/gbuffer.glsl"
#include "lib/cone.glsl"
#include "lib/brdf.glsl"
#include "lib/specular_cone.glsl"
#include "lib/cone_pixels.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_IMAGE_OUT, rgba32f) uniform image2D image_out;
uniform float ao_distance;

#ifdef TRACE_UNSHARED
#define traced_count unshared_count
#define traced_pixels unshared_pixels
#else
#define traced_count pixel_count
#define traced_pixels pixels
#endif

void main() {
    if (gl_GlobalInvocationID.x >= traced_count) return;
    uvec2 entry = traced_pixels[gl_GlobalInvocationID.x];
    ivec2 pixel = unpack_pixel(entry.x);
    Surface s = read_gbuffer(pixel);
    vec3 radiance = vec3(0.0);
    if ((entry.y & PIXEL_DIFFUSE_CONES) != 0u) {
        vec3 gathered = trace_diffuse(s.position, s.normal, surface_level(s.position), 1e9, SCREEN_DIFFUSE_READING).rgb;
        if (is_anchor(pixel)) imageStore(diffuse_in, pixel / 2, vec4(gathered, 1.0));
        radiance += hemisphere_reflectance(s, include_diffuse, include_specular) * gathered;
    }
    if ((entry.y & PIXEL_SPECULAR_CONE) != 0u) {
        vec3 incoming = specular_incoming(s);
        if (is_anchor(pixel)) imageStore(specular_in, pixel / 2, vec4(incoming, 1.0));
        radiance += specular_reflectance(s) * incoming;
    }
    if ((entry.y & PIXEL_AO_CONES) != 0u) {
        float occlusion = trace_diffuse(s.position, s.normal, surface_level(s.position), ao_distance, SCREEN_DIFFUSE_READING).a;
        radiance += vec3(1.0 - clamp(occlusion, 0.0, 1.0));
    }
    imageStore(image_out, pixel, imageLoad(image_out, pixel) + vec4(radiance, 0.0));
}
