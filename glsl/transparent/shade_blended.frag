#version 450 core
// Blended surfaces (alphaMode BLEND) seen over the opaque image, in any order: weighted,
// blended order-independent transparency (McGuire and Bavoil 2013). Each fragment's light C
// (emission, the lights' direct light through their shadow maps and, where the frame has
// voxels, the diffuse light they gathered, the sky's light through them and a specular cone)
// is added to the sums with its coverage a and a weight w falling with its distance z:
//   sums += w a (C, 1),  w = clamp(10 / (1e-5 + (z/5)^2 + (z/200)^6), 1e-2, 3e3)  (their equation 9),
//   coverage = a + coverage (1 - a)  (1 - the revealage prod (1 - a): both targets start at zero);
// transparent/composite.frag divides them out. The G-buffer's depth hides
// what lies behind the opaque surfaces.
#include "lib/material.glsl"
#include "lib/lights.glsl"
#include "lib/brdf.glsl"
#include "lib/camera.glsl"
#include "lib/gbuffer.glsl"
#ifdef VOXELS
#include "lib/voxel_interpolation.glsl"
#include "lib/specular_cone.glsl"
#endif
#ifdef SKY
#define SKY_LIGHT true
#else
#define SKY_LIGHT false
#endif

in vec3 world_position;
in vec3 world_normal;
flat in uint material;
in vec4 world_tangent;
in vec3 vertex_color;
in vec4 map_coordinates01;
in vec4 map_coordinates23;
uniform bool include_direct;
uniform bool include_diffuse;
uniform bool include_specular;
layout(location = 0) out vec4 out_sums;
layout(location = 1) out vec4 out_coverage;

void main() {
    MapCoordinates coordinates = MapCoordinates(map_coordinates01, map_coordinates23);
    MaterialSample m = sample_material(material, coordinates, vertex_color);
    float a = clamp(m.alpha, 0.0, 1.0);
    vec3 n = shading_normal(material, normalize(world_normal) * (gl_FrontFacing ? 1.0 : -1.0), world_tangent, coordinates);
    Surface s = Surface(true, world_position, n, m.albedo, m.roughness, m.metalness, m.dielectric_f0, m.emission);
    vec3 v = to_camera(s.position);
    vec3 radiance = vec3(0.0);
    if (include_direct) {
        radiance += gl_FrontFacing ? m.emission : vec3(0.0);  // one-sided emitters, as in the G-buffer
        for (int i = 0; i < light_count; ++i) {
            vec3 l;
            vec3 irradiance = light_irradiance(i, s.position, s.normal, 0.0, true, l);
            if (any(greaterThan(irradiance, vec3(0.0))))
                radiance += brdf(s.normal, l, v, s.albedo, s.roughness, s.metalness, s.dielectric_f0) * irradiance;
        }
    }
#ifdef VOXELS
    vec3 gathered_reflectance = hemisphere_reflectance(s, include_diffuse, include_specular);
    vec3 sky_reflectance = hemisphere_reflectance(s, include_direct, include_specular);
    VoxelInterpolation voxels = interpolate_voxels(s, any(greaterThan(gathered_reflectance, vec3(0.0))), false,
                                                   SKY_LIGHT && any(greaterThan(sky_reflectance, vec3(0.0))));
    radiance += gathered_reflectance * voxels.gathered + sky_reflectance / PI * voxels.sky_irradiance;
    if (include_specular && traces_specular_cone(s)) radiance += specular_reflectance(s) * specular_incoming(s);
#endif
    float z = distance(camera.position.xyz, s.position);
    float w = a * clamp(10.0 / (1e-5 + pow(z / 5.0, 2.0) + pow(z / 200.0, 6.0)), 1e-2, 3e3);
    out_sums = w * vec4(radiance, 1.0);
    out_coverage = vec4(a);
}
