#version 450 core
// The emitters' light at each covered voxel, shadowed, where surfaces emit: at the voxel's
// surface point along its normalized mean normal (for a source that fills the hemisphere the
// fragments' mean irradiance is that, not its product with the mean normal's length: a white
// furnace's edge voxels get 0.98 of their light at 64^3 instead of about 0.68),
//   E = sum_patches V_patch E_patch   (rgb; lib/emitters.glsl)
// and the fraction of the unshadowed light that arrives, E / E_unshadowed (a; 1 where none
// arrives), which the pixels interpolate. Light injection adds rho / pi E. Runs over a segment
// of the class list (all covered voxels, or one interleave class a frame in the viewer) when
// the voxels or the emitters change, not when a light moves, or over the touched voxels (those a
// scrolled clipmap level took in).
#include "lib/voxel_surface.glsl"
#include "lib/cone.glsl"
#include "lib/emitters.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_EMITTER_IRRADIANCE) writeonly buffer VoxelEmitterIrradiance { uvec2 emitter_irradiance_out[]; };
#include "lib/voxel_list.glsl"

// Fraction of a patch p (in a voxel of `level`) sees, from one cone towards the patch's centre
// as wide as its sphere.
// The cone stops before its lookups reach the patch's plane, behind which its own voxels and
// the surface it may lie on are. A trilinear lookup at level m weighs the cells whose centres
// lie within one cell (d/2 = t tan a wide, lib/cone.glsl) of the sample, and a cell's content
// reaches half a cell past its centre: 1.5 t tan a in all. At height h(t) = h0 - t c over the
// plane (c = cosine between the cone and the plane's normal), the cone reads up to
//   h(t) - 1.5 t tan a = depth + voxel   (voxel: the side of p's voxels)
// It reads the nearest mip level: blending two levels cost twice the time for the same
// shadows (a lamp under the ceiling 0.0040 blended, 0.0029 nearest; a glowing box 0.0104 both).
float patch_visibility(vec3 p, vec3 n, int level, EmitterPatch e) {
    vec3 to_patch = e.sphere.xyz - p;
    float d = length(to_patch);
    vec3 w = to_patch / max(d, 1e-6);
    float tan_half_angle = clamp(e.sphere.w / max(d, 1e-6), 0.0, 1.0);
    float c = max(dot(w, -e.plane.xyz), 0.0);
    float voxel = level_voxel_size[level];
    float reach = (d * c - e.plane.w - voxel) / (c + 1.5 * tan_half_angle);
    if (reach <= voxel) return 1.0;
    ConeReading reading = EMITTER_READING;
    reading.wide = tan_half_angle > sqrt(0.5);  // wider than 35.3 degrees
    return 1.0 - min(trace_cone(p, n, level, w, tan_half_angle, reach, reading).a, 1.0);
}

uniform uint lit_levels;  // bit k: level k's voxels take their light now, the others keep theirs

void main() {
    ivec3 v;
    if (!segment_voxel(gl_GlobalInvocationID.x, v)) return;
    if (!in_level_mask(lit_levels, v)) return;
    uint record = voxel_record(v);
    if (record == NO_RECORD) return;  // a touched voxel the voxelization emptied
    for (int side = 0; side < VOXEL_SIDES; ++side) {  // each side lit through its own normal
        VoxelSurface s = voxel_surface(v, record, side);
        vec3 shadowed = vec3(0.0), unshadowed = vec3(0.0);
        if (dot(s.mean_normal, s.mean_normal) > 0.0) {
            vec3 n = normalize(s.mean_normal);
            for (int i = 0; i < emitter_patch_count; ++i) {
                EmitterPatch e = emitter_patches[i];
                vec3 irradiance = patch_irradiance(s.position, n, e);
                if (any(greaterThan(irradiance, vec3(0.0)))) {
                    unshadowed += irradiance;
                    shadowed += irradiance * patch_visibility(s.position, n, voxel_level(v), e);
                }
            }
        }
        float total = unshadowed.r + unshadowed.g + unshadowed.b;
        emitter_irradiance_out[side_value(record, side)] = pack_value(vec4(shadowed, total > 0.0 ? (shadowed.r + shadowed.g + shadowed.b) / total : 1.0));
    }
}
