#version 450 core
// Deferred direct lighting: Lo = Le + sum_lights f(l, v) E_l, from point/spot/directional lights.
#include "lib/gbuffer.glsl"
#include "lib/lights.glsl"
#include "lib/brdf.glsl"
#include "lib/camera.glsl"

layout(location = 0) out vec4 out_radiance;

void main() {
    Surface s = read_gbuffer(ivec2(gl_FragCoord.xy));
    if (!s.covered) { out_radiance = vec4(0.0); return; }
    vec3 v = to_camera(s.position);
    vec3 radiance = s.emission;
    for (int i = 0; i < light_count; ++i) {
        vec3 l;
        vec3 irradiance = light_irradiance(i, s.position, s.normal, 0.0, true, l);
        if (any(greaterThan(irradiance, vec3(0.0))))
            radiance += brdf(s.normal, l, v, s.albedo, s.roughness, s.metalness, s.dielectric_f0) * irradiance;
    }
    out_radiance = vec4(radiance, 1.0);
}
