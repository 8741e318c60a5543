#version 450 core
// The cones of the pixels cone_trace.frag listed, added to the image:
//   diffuse:  (1 - m) k_d sum_j w_j Lv(p, w_j, a_j), where no voxel around p faces its way
//   specular: F(w_o . n) Lv(p, w_s, a_s), w_s = 2 (w_o . n) n - w_o, with the aperture of the
//             normalized Blinn-Phong lobe of exponent 2/r^4 - 2
// Dispatched indirectly with the group count the listing counted.
#include "lib/gbuffer.glsl"
#include "lib/cone.glsl"
#include "lib/brdf.glsl"
#include "lib/cone_pixels.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_IMAGE_OUT, rgba32f) uniform image2D image_out;
uniform vec3 camera_position;

// Specular cone aperture from the normalized Blinn-Phong lobe of exponent s = 2/r^4 - 2:
// sigma^2 = c r^4 / (1 - r^4) with c = 2 (the lobe around w_s is twice as wide as around h),
// sin(a/2) = sigma, tan(a/2) = sqrt(sigma^2 / (1 - sigma^2)); r = 0 gives the one-voxel
// mirror cone (the marcher floors the diameter at a voxel), r = 1 a hemisphere.
float specular_tan_half_angle(float roughness) {
    float r4 = pow(roughness, 4.0);
    if (r4 >= 1.0) return 1e4;
    float sigma2 = min(2.0 * r4 / (1.0 - r4), 1.0);
    return sigma2 >= 1.0 ? 1e4 : sqrt(sigma2 / (1.0 - sigma2));
}

void main() {
    if (gl_GlobalInvocationID.x >= pixel_count) return;
    uvec2 entry = pixels[gl_GlobalInvocationID.x];
    ivec2 pixel = ivec2(entry.x & 0xffffu, entry.x >> 16);
    Surface s = read_gbuffer(pixel);
    vec3 radiance = vec3(0.0);
    if ((entry.y & PIXEL_DIFFUSE_CONES) != 0u)
        radiance += (1.0 - s.metalness) * s.albedo * trace_diffuse(s.position, s.normal, 1e9).rgb;
    if ((entry.y & PIXEL_SPECULAR_CONE) != 0u) {
        vec3 wo = normalize(camera_position - s.position);
        float cos_o = max(dot(wo, s.normal), 0.0);
        vec3 ws = 2.0 * cos_o * s.normal - wo;
        vec4 cone = trace_cone(s.position, s.normal, ws, specular_tan_half_angle(s.roughness), 1e9, true);
        radiance += fresnel_schlick(specular_f0(s.albedo, s.metalness, s.dielectric_f0), cos_o) * cone.rgb;
    }
    imageStore(image_out, pixel, imageLoad(image_out, pixel) + vec4(radiance, 0.0));
}
