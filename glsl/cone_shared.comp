#version 450 core
// The specular term of the pixels between anchors (the shared list): Lv from the
// anchors around the pixel (even x and y, two pixels apart; cone_pixels.comp traced them),
// weighted bilinearly and by how well each stands for the pixel (same roughness, same plane,
// facing the same way), times the pixel's own F(w_o . n); a pixel no anchor stands for traces
// its own cone. A specular cone spans many pixels' worth of directions, so its Lv varies
// little from pixel to pixel on one surface.
#include "lib/gbuffer.glsl"
#include "lib/specular_cone.glsl"
#include "lib/cone_pixels.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_IMAGE_OUT, rgba32f) uniform image2D image_out;

#define NORMAL_EXPONENT 32.0   // an anchor whose normal is 10 degrees off counts 0.6
#define PLANE_TOLERANCE 0.01   // of the distance to the camera
#define ROUGHNESS_TOLERANCE 0.02

// How well the Lv of anchor a stands for surface s's.
float anchor_similarity(Surface a, Surface s) {
    if (!a.covered || abs(a.roughness - s.roughness) > ROUGHNESS_TOLERANCE) return 0.0;
    if (abs(dot(a.position - s.position, s.normal)) > PLANE_TOLERANCE * distance(camera_position, s.position)) return 0.0;
    return pow(max(dot(a.normal, s.normal), 0.0), NORMAL_EXPONENT);
}

void main() {
    if (gl_GlobalInvocationID.x >= shared_count) return;
    ivec2 pixel = unpack_pixel(shared_pixels[gl_GlobalInvocationID.x]);
    Surface s = read_gbuffer(pixel);
    ivec2 size = textureSize(gbuffer_position, 0);
    ivec2 base = pixel / 2;                    // the anchor at or before the pixel, in anchors
    vec2 f = vec2(pixel - 2 * base) * 0.5;     // 0 on an anchor's row or column, 0.5 between
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 corner = ivec2(k & 1, k >> 1);
        vec2 bilinear = mix(1.0 - f, f, vec2(corner));
        ivec2 anchor = 2 * (base + corner);
        if (bilinear.x * bilinear.y == 0.0 || any(greaterThanEqual(anchor, size))) continue;
        Surface a = read_gbuffer(anchor);
        // An anchor traced a cone where its surface reflects specularly.
        if (!has_specular_layer(specular_f0(a.albedo, a.metalness, a.dielectric_f0))) continue;
        float weight = bilinear.x * bilinear.y * anchor_similarity(a, s);
        sum += weight * imageLoad(specular_in, base + corner).rgb;
        total += weight;
    }
    vec3 incoming = total > 0.05 ? sum / total : specular_incoming(s);
    imageStore(image_out, pixel, imageLoad(image_out, pixel) + vec4(specular_fresnel(s) * incoming, 0.0));
}
