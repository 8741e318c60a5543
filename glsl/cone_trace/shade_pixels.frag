#version 450 core
// The image over the G-buffer: direct light (with emission and the light of emissive surfaces)
// plus cone-traced indirect light.
//   direct:   the lighting pass's image + c_d / pi V E_emitters(p, n): the emitters' light
//             exact at p (lib/emitters.glsl), times the fraction V of it that arrives,
//             interpolated from the voxels around p (emitter_light/light_voxels.comp) + c_d / pi
//             E_sky: the environment's light through the voxels, interpolated likewise
//             (sky_light/trace_sky_cones.comp); where no surface is, the environment itself
//   diffuse:  Lo = c_d sum_j w_j Lv(p, w_j, a_j), the lecture's 6 cones, with c_d the diffuse
//             layer's albedo seen from the camera, (1 - m) k_d (1 - F(w_o . n)). They are
//             traced once per voxel whenever the voxel radiance changes (gather/trace_anchor_cones.comp);
//             a pixel interpolates the gathers of the voxels around p whose surfaces face its
//             way; where none does (a thin surface seen from behind) the cones are traced at
//             the anchors (even x and y) and shared with the pixels between where they match
//   specular: Lo = A(w_o) Lv(p, w_s, a_s), w_s = 2 (w_o . n) n - w_o, A the specular layer's
//             directional albedo (lib/brdf.glsl specular_layer_albedo), traced at every
//             other pixel in x and y and shared with the pixels between where they match
//   AO:       1 - sum_j w_j alpha_j within ao_distance, traced per pixel
// The cones run in cone_trace/trace_listed_pixels.comp (the anchors' and the unshared ones, and
// every pixel's AO cones) and cone_trace/share_anchor_cones.comp (the pixels between anchors)
// over the pixels listed here, so pixels that need none never wait on them (nor carry the cone
// marching's code: on llvmpipe a branch never taken still cost a third of this pass).
#include "lib/gbuffer.glsl"
#include "lib/voxel_interpolation.glsl"
#include "lib/cone.glsl"
#include "lib/brdf.glsl"
#include "lib/specular_cone.glsl"
#include "lib/cone_pixels.glsl"
// EMITTERS is defined in the program for scenes where surfaces emit, SKY for scenes with an
// environment (passes/cone_trace.py): on llvmpipe their code costs the other scenes' pixels
// time even where it is skipped.
#ifdef EMITTERS
#include "lib/emitters.glsl"
#define EMITTER_LIGHT true
#else
#define EMITTER_LIGHT false
#endif
#ifdef SKY
#define SKY_LIGHT true
#else
#define SKY_LIGHT false
#endif

layout(binding = TEX_DIRECT_LIGHT) uniform sampler2D direct_light;
uniform int output_kind;
uniform bool include_direct;
uniform float pixel_angle;  // radians between neighbouring pixels' rays
layout(location = 0) out vec4 out_radiance;

// The direction of the camera ray through the centre of a pixel.
vec3 view_direction(ivec2 pixel) {
    vec3 origin, direction;
    camera_ray((vec2(pixel) + 0.5) / vec2(textureSize(gbuffer_position, 0)) * 2.0 - 1.0, origin, direction);
    return direction;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    if (is_anchor(pixel)) imageStore(diffuse_in, pixel / 2, vec4(0.0));  // no diffuse cones traced (yet)
    Surface s = read_gbuffer(pixel);
    if (!s.covered) {  // the environment where no surface is, as the camera sees emitters
        bool sky = SKY_LIGHT && include_direct && output_kind == OUTPUT_RADIANCE;
        out_radiance = vec4(sky ? environment_radiance(view_direction(pixel), 0.5 * pixel_angle) : vec3(0.0), 0.0);
        return;
    }
    if (output_kind == OUTPUT_AO) {
        list_cone_pixel(uvec2(pack_pixel(pixel), PIXEL_AO_CONES));
        out_radiance = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    // What the surface reflects of the voxels' gathered light and of the sky's and the
    // emitters' light: the diffuse layer's share (indirect and direct light), and the specular
    // layer's where its lobe spans the hemisphere (the specular term, as what a cone gathers).
    vec3 gathered_reflectance = hemisphere_reflectance(s, include_diffuse, include_specular);
    vec3 light_reflectance = hemisphere_reflectance(s, include_direct, include_specular);
    bool gathers = any(greaterThan(gathered_reflectance, vec3(0.0)));
    bool lit = any(greaterThan(light_reflectance, vec3(0.0)));
    bool lit_by_emitters = EMITTER_LIGHT && lit;
    bool lit_by_sky = SKY_LIGHT && lit;
    VoxelInterpolation voxels = interpolate_voxels(s, gathers, lit_by_emitters, lit_by_sky);
    vec3 radiance = include_direct ? texelFetch(direct_light, pixel, 0).rgb : vec3(0.0);
#ifdef EMITTERS
    if (lit_by_emitters)
        radiance += light_reflectance / PI * emitter_irradiance(s.position, s.normal) * voxels.emitter_visibility;
#endif
    if (lit_by_sky) radiance += light_reflectance / PI * voxels.sky_irradiance;
    // Pixels that need cones are listed (lib/cone_pixels.glsl): the diffuse cones where no
    // voxel faces the pixel's way, the specular cone where the surface reflects specularly
    // through a lobe narrower than the hemisphere; traced at the anchors (even x and y) and
    // shared with the pixels between them.
    uint cones = 0u, shared_cones = 0u;
    bool anchor = is_anchor(pixel);
    if (gathers) {
        if (voxels.gathered_found) radiance += gathered_reflectance * voxels.gathered;
        else if (anchor) cones |= PIXEL_DIFFUSE_CONES;
        else shared_cones |= PIXEL_DIFFUSE_CONES;
    }
    if (include_specular && traces_specular_cone(s)) {
        // Between anchors two pixels apart the reflected direction turns by about four pixels'
        // angle: a cone at least that wide is shared, a narrower one (near a mirror) is not.
        bool shared_cone = atan(specular_tan_half_angle(s.roughness)) >= 4.0 * pixel_angle;
        if (anchor || !shared_cone) cones |= PIXEL_SPECULAR_CONE;
        else shared_cones |= PIXEL_SPECULAR_CONE;
    }
    if (cones != 0u) list_cone_pixel(uvec2(pack_pixel(pixel), cones));
    if (shared_cones != 0u) list_shared_pixel(uvec2(pack_pixel(pixel), shared_cones));
    out_radiance = vec4(radiance, 1.0);
}
