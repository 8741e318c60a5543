#version 450 core
// One diffuse bounce inside the grid: every covered voxel (from the resolve pass's list)
// gathers light with the 6 diffuse cones from the previous radiance (its six face views) and
// re-emits it:
//   L_out = L_base + k_d sum_j w_j L_prev(p, w_j)
// (L_base = emission + direct light from voxelization). Repeating it converges to the
// infinite-bounce radiance because k_d < 1. A list keeps every invocation busy: covered voxels
// are a thin shell, so a dispatch over the whole grid would leave most SIMD lanes idle.
// Amortized (the viewer): only the voxels of one interleave class gather again this frame;
// the others reuse their last gather (kept in `gathered`) with this frame's direct light.
// The list follows rasterization order, so a voxel keeps its class from frame to frame.
#include "engine_constants.glsl"
#include "lib/cone.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(binding = TEX_VOXEL_RADIANCE) uniform sampler3D base_radiance;
layout(binding = TEX_VOXEL_NORMAL) uniform sampler3D voxel_normal;
layout(binding = TEX_VOXEL_ALBEDO) uniform sampler3D voxel_albedo;
layout(binding = IMG_OUT_DIRECTIONAL, rgba16f) uniform writeonly image3D out_directional[VOXEL_FACES];
layout(binding = IMG_GATHERED, rgba16f) uniform image3D gathered;
uniform int interleave;        // voxels are split into this many classes...
uniform int interleave_phase;  // ...and this class gathers again
layout(std430, binding = SSBO_OCCUPIED) readonly buffer OccupiedVoxels { uint occupied_count; uint occupied[]; };

void main() {
    if (gl_GlobalInvocationID.x >= occupied_count) return;
    ivec3 v = unpack_voxel(occupied[gl_GlobalInvocationID.x]);
    vec3 mean_normal = texelFetch(voxel_normal, v, 0).xyz;
    vec3 albedo = texelFetch(voxel_albedo, v, 0).rgb;
    vec3 incoming = vec3(0.0);  // sum_j w_j L_prev(p, w_j)
    // Classes are whole work groups of the list, so a group either traces or reuses, together.
    if (int(gl_WorkGroupID.x) % interleave != interleave_phase) {
        incoming = imageLoad(gathered, v).rgb;
    } else if (dot(mean_normal, mean_normal) > 1e-6 && any(greaterThan(albedo, vec3(0.0)))) {
        incoming = trace_diffuse(voxel_center(v), normalize(mean_normal), 1e9).rgb;
        if (interleave > 1) imageStore(gathered, v, vec4(incoming, 1.0));
    }
    vec3 radiance = texelFetch(base_radiance, v, 0).rgb + albedo * incoming;
    for (int f = 0; f < VOXEL_FACES; ++f) {
        float coverage = face_coverage(mean_normal, f);
        imageStore(out_directional[f], v, vec4(radiance * coverage, coverage));
    }
}
