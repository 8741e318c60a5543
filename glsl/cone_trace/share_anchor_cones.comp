#version 450 core
// The cones' light of the pixels between anchors (the shared list), from the anchors around
// the pixel (even x and y, two pixels apart; cone_trace/trace_listed_pixels.comp traced them), weighted
// bilinearly and by how well each stands for the pixel (same plane, facing the same way; for
// the specular cone the same roughness too):
//   diffuse:  c_d, the pixel's own diffuse layer albedo, times the anchors' sum_j w_j Lv(p, w_j),
//             where no voxel faces the pixel's way (a thin surface seen from behind)
//   specular: A(w_o), the pixel's own specular layer albedo, times the anchors' Lv(p, w_s, a_s)
// A term no anchor stands for is listed for cone_trace/trace_listed_pixels.comp (the pixel traces its own cones
// there, in groups of such pixels, not beside lanes that only read anchors). The diffuse cones
// span a hemisphere and a specular cone many pixels' worth of directions, so what they gather
// varies little from pixel to pixel on one surface.
#include "lib/gbuffer.glsl"
#include "lib/brdf.glsl"
#include "lib/specular_cone.glsl"
#include "lib/cone_pixels.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_IMAGE_OUT, rgba32f) uniform image2D image_out;

#define NORMAL_EXPONENT 32.0   // an anchor whose normal is 10 degrees off counts 0.6
#define PLANE_TOLERANCE 0.01   // of the distance to the camera
#define ROUGHNESS_TOLERANCE 0.02
#define SHARED_WEIGHT_MIN 0.05 // of the bilinear weights' sum, 1: less, and the pixel traces its own

// How well the cones of anchor a stand for surface s's: same plane, facing the same way.
float anchor_similarity(Surface a, Surface s) {
    if (!a.covered) return 0.0;
    if (abs(dot(a.position - s.position, s.normal)) > PLANE_TOLERANCE * camera_distance(s.position)) return 0.0;
    return pow(max(dot(a.normal, s.normal), 0.0), NORMAL_EXPONENT);
}

void main() {
    if (gl_GlobalInvocationID.x >= shared_count) return;
    uvec2 entry = shared_pixels[gl_GlobalInvocationID.x];
    ivec2 pixel = unpack_pixel(entry.x);
    bool diffuse = (entry.y & PIXEL_DIFFUSE_CONES) != 0u, specular = (entry.y & PIXEL_SPECULAR_CONE) != 0u;
    Surface s = read_gbuffer(pixel);
    ivec2 size = textureSize(gbuffer_position, 0);
    ivec2 base = pixel / 2;                    // the anchor at or before the pixel, in anchors
    vec2 f = vec2(pixel - 2 * base) * 0.5;     // 0 on an anchor's row or column, 0.5 between
    vec3 diffuse_sum = vec3(0.0), specular_sum = vec3(0.0);
    float diffuse_total = 0.0, specular_total = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 corner = ivec2(k & 1, k >> 1);
        vec2 bilinear = mix(1.0 - f, f, vec2(corner));
        ivec2 anchor = 2 * (base + corner);
        if (bilinear.x * bilinear.y == 0.0 || any(greaterThanEqual(anchor, size))) continue;
        Surface a = read_gbuffer(anchor);
        float weight = bilinear.x * bilinear.y * anchor_similarity(a, s);
        if (weight <= 0.0) continue;
        vec4 gathered = diffuse ? imageLoad(diffuse_in, base + corner) : vec4(0.0);
        if (gathered.a > 0.0) {  // the anchor traced diffuse cones
            diffuse_sum += weight * gathered.rgb;
            diffuse_total += weight;
        }
        // An anchor traced a specular cone where its surface reflects specularly.
        if (specular && traces_specular_cone(a) && abs(a.roughness - s.roughness) <= ROUGHNESS_TOLERANCE) {
            specular_sum += weight * imageLoad(specular_in, base + corner).rgb;
            specular_total += weight;
        }
    }
    vec3 radiance = vec3(0.0);
    uint unshared = 0u;  // the terms this pixel traces itself
    if (diffuse) {
        if (diffuse_total > SHARED_WEIGHT_MIN)
            radiance += hemisphere_reflectance(s, include_diffuse, include_specular) * diffuse_sum / diffuse_total;
        else unshared |= PIXEL_DIFFUSE_CONES;
    }
    if (specular) {
        if (specular_total > SHARED_WEIGHT_MIN) radiance += specular_reflectance(s) * specular_sum / specular_total;
        else unshared |= PIXEL_SPECULAR_CONE;
    }
    imageStore(image_out, pixel, imageLoad(image_out, pixel) + vec4(radiance, 0.0));
    if (unshared != 0u) list_unshared_pixel(uvec2(entry.x, unshared));
}
