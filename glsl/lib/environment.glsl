// The light from beyond the scene (engine.scene.model.Environment, uploaded by
// scene_buffers.EnvironmentMap): an equirectangular map of linear radiance, a uniform sky being a
// map of one texel. Direction d, turned into the map's frame, reads
//   u = atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi     (Mitsuba's envmap)
// at the mip level whose texels are as wide as the cone around d (its prefiltering).
#include "engine_constants.glsl"

layout(binding = TEX_ENVIRONMENT) uniform sampler2D environment_map;  // repeats in u, clamps in v
uniform bool environment_present;
uniform float environment_scale;
uniform mat3 environment_rotation;      // world directions into the map's frame
uniform float environment_texel_angle;  // radians a texel of level 0 spans in u: 2 pi / width

// Mean radiance over the cone of half-angle `half_angle` around direction d.
vec3 environment_radiance(vec3 d, float half_angle) {
    if (!environment_present) return vec3(0.0);
    vec3 m = environment_rotation * d;
    vec2 uv = vec2(atan(m.x, -m.z) / (2.0 * PI), acos(clamp(m.y, -1.0, 1.0)) / PI);
    float level = log2(max(2.0 * half_angle / environment_texel_angle, 1.0));
    return environment_scale * textureLod(environment_map, uv, level).rgb;
}
