#version 450 core
// Light injection, over the covered voxels: the base radiance each voxel's surface sends out
// before any bounce, evaluated at its surface point with its mean normal:
//   L_base = L_e + rho / pi * (sum_lights E_l + E_emitters + E_sky), rho the voxel's
// reflectance (voxelize/rasterize.frag), where dot(mean normal, l) in E_l is the mean of the fragments'
// cosines, E_emitters the emitters' shadowed light (emitter_light/light_voxels.comp) and E_sky the
// environment's (sky_light/trace_sky_cones.comp). Runs when a light or a
// shadow map changes, without revoxelizing, over a segment of a voxel list: the covered list
// (every voxel), the class list (in progressive frames one interleave class) or the voxels a
// voxelization touched.
#include "lib/voxel_surface.glsl"
#include "lib/voxel_light.glsl"
#include "lib/lights.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_BASE) writeonly buffer VoxelBase { uvec2 base_out[]; };
#include "lib/voxel_list.glsl"

void main() {
    ivec3 v;
    if (!segment_voxel(gl_GlobalInvocationID.x, v)) return;
    uint record = voxel_record(v);
    if (record == NO_RECORD) return;  // a touched voxel the voxelization emptied
    VoxelSurface s = voxel_surface(v, record, 0);  // side 0 says how many sides there are
    int sides = s.sides;
    for (int side = 0; side < sides; ++side) {  // each side lit by its own normal and shadow lookup
        if (side > 0) s = voxel_surface(v, record, side);
        uint at = side_value(record, side);
        vec3 irradiance = vec3(0.0);
        if (dot(s.mean_normal, s.mean_normal) > 0.0 && any(greaterThan(s.albedo, vec3(0.0)))) {
            for (int i = 0; i < light_count; ++i) {
                vec3 l;
                irradiance += light_irradiance(i, s.position, s.mean_normal, VOXEL_SHADOW_LIFT * voxel_extent(v), false, l);
            }
            if (voxel_emitters) irradiance += unpack_value(voxel_emitter_irradiance[at]).rgb;
            if (voxel_sky) irradiance += unpack_value(voxel_sky_irradiance[at]).rgb;
        }
        base_out[at] = pack_value(vec4(s.emission + s.albedo / PI * irradiance, 1.0));
    }
}
