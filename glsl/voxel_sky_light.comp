#version 450 core
// The environment's light at the voxels of a list segment (the gather's anchors; the others
// interpolate them, voxel_fill.comp), where the scene has one: at the voxel's surface point
// along its normalized mean normal (as the emitters' light, voxel_emitter_light.comp), through
// SKY_CONE_COUNT cones over the hemisphere (engine/constants.py sky_cones), each reading the
// voxels one level finer than its footprint (SKY_CONE_LEVEL_OFFSET),
//   E = pi sum_j w_j (1 - a_j) L_sky(w_j, a)      (a_j: the cone's opacity on its way out)
// so a cone that leaves the grid unoccluded brings the sky's radiance around its direction,
// prefiltered to its aperture. Light injection adds rho / pi E; the pixels interpolate E.
// Runs when the voxels or the environment change, over every class at once or one
// interleave class a frame in the viewer.
#include "lib/voxel_surface.glsl"
#include "lib/cone.glsl"
#include "lib/environment.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = IMG_SKY_LIGHT_OUT, rgba16f) uniform writeonly image3D sky_light_out;
layout(std430, binding = SSBO_VOXEL_LIST) readonly buffer VoxelList { uint voxel_list[]; };
uniform uint first;  // the segment of the list to light
uniform uint count;

void main() {
    if (gl_GlobalInvocationID.x >= count) return;
    ivec3 v = unpack_voxel(voxel_list[first + gl_GlobalInvocationID.x]);
    VoxelSurface s = voxel_surface(v);
    vec3 irradiance = vec3(0.0);
    if (dot(s.mean_normal, s.mean_normal) > 0.0) {
        vec3 n = normalize(s.mean_normal);
        mat3 frame = tangent_frame(n);
        float tan_half = tan(SKY_CONE_HALF_ANGLE);
        for (int j = 0; j < SKY_CONE_COUNT; ++j) {
            vec3 w = frame * SKY_CONE_DIRECTIONS[j];
            float opacity = trace_cone(s.position, n, w, tan_half, 1e9, false, true, false, SKY_CONE_LEVEL_OFFSET, 1.0).a;
            irradiance += SKY_CONE_WEIGHTS[j] * (1.0 - min(opacity, 1.0)) * environment_radiance(w, SKY_CONE_HALF_ANGLE);
        }
        irradiance *= PI;  // E = pi x the cosine-weighted mean radiance
    }
    imageStore(sky_light_out, v, vec4(irradiance, 1.0));
}
