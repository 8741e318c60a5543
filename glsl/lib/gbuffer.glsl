// Reading the G-buffer written by gbuffer/draw_surfaces.frag.
#include "engine_constants.glsl"

layout(binding = TEX_GBUF_POSITION) uniform sampler2D gbuffer_position;
layout(binding = TEX_GBUF_NORMAL) uniform sampler2D gbuffer_normal;
layout(binding = TEX_GBUF_ALBEDO) uniform sampler2D gbuffer_albedo;
layout(binding = TEX_GBUF_EMISSION) uniform sampler2D gbuffer_emission;

struct Surface {
    bool covered;
    vec3 position;
    vec3 normal;
    vec3 albedo;
    float roughness;
    float metalness;
    float dielectric_f0;
    vec3 emission;
};

Surface read_gbuffer(ivec2 pixel) {
    Surface s;
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    vec4 n = texelFetch(gbuffer_normal, pixel, 0);
    vec4 a = texelFetch(gbuffer_albedo, pixel, 0);
    vec4 e = texelFetch(gbuffer_emission, pixel, 0);
    s.covered = p.w > 0.0;
    s.position = p.xyz;
    s.normal = normalize(n.xyz);
    s.roughness = n.w;
    s.albedo = a.rgb;
    s.metalness = a.a;
    s.emission = e.rgb;
    s.dielectric_f0 = e.a;
    return s;
}
