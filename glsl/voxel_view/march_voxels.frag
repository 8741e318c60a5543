#version 450 core
// Voxel views: a ray from the camera through each pixel, marched through one mip level of a
// voxel volume and composited front to back (radiance, encoded normals 0.5 n + 0.5, albedo),
// then divided by the opacity gathered so that partly covered mip cells show their value.
#include "engine_constants.glsl"
#include "lib/voxel.glsl"
#include "lib/camera.glsl"

layout(binding = TEX_VOXEL_INSPECT) uniform sampler3D volume;
uniform int show;
uniform float mip;
uniform int shown_level;  // the level of the grid shown
uniform vec2 viewport_size;
layout(location = 0) out vec4 out_value;

void main() {
    vec3 origin, direction;
    camera_ray(gl_FragCoord.xy / viewport_size * 2.0 - 1.0, origin, direction);
    // Clip the ray to the level's cube.
    float cell = level_voxel_size[shown_level] * exp2(mip);
    vec3 box_min = level_region_min[shown_level], box_max = box_min + level_voxel_size[shown_level] * float(voxel_grid);
    vec3 t0 = (box_min - origin) / direction, t1 = (box_max - origin) / direction;
    float t_enter = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float t_exit = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    float step_length = 0.25 * cell;
    vec4 sum = vec4(0.0);
    for (float t = t_enter; t < t_exit && sum.a < 0.99; t += step_length) {
        vec3 uvw = level_uvw(origin + direction * t, shown_level);
        // Nearest-texel lookup shows the voxels as blocks.
        float side = float(textureSize(volume, int(mip)).x);
        vec3 texel = (floor(uvw * side) + 0.5) / side;
        vec4 s = textureLod(volume, stacked_uvw(texel, shown_level, 0, 1, side), mip);
        if (s.a <= 0.0) continue;
        vec3 value = s.rgb / s.a;
        if (show == SHOW_NORMAL) value = 0.5 * normalize(value) + 0.5;
        float alpha = 1.0 - pow(1.0 - min(s.a, 1.0), step_length / cell);
        sum.rgb += (1.0 - sum.a) * alpha * value;
        sum.a += (1.0 - sum.a) * alpha;
    }
    out_value = vec4(sum.a > 0.0 ? sum.rgb / sum.a : vec3(0.0), 1.0);
}
