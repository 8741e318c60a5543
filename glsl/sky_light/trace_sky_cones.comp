#version 450 core
// The environment's light at the gather's anchors among the voxels of a list segment (the others
// interpolate them, gather/interpolate_from_anchors.comp, and sky_light/filter_sky_light.comp averages the result), where the
// scene has one: at the voxel's surface point along its normalized mean normal (as the
// emitters' light, emitter_light/light_voxels.comp), through SKY_CONE_COUNT cones over the hemisphere,
// uniform in solid angle and offset by the voxel's own jitter (engine/core/constants.py), each
// reading the voxels finer than its footprint (SKY_CONE_LEVEL_OFFSET),
//   E = pi sum_j z_j (1 - a_j) L_sky(w_j, a) / sum_j z_j   (z_j = n . w_j; a_j: the cone's
//                                                            opacity on its way out)
// so a cone that leaves the grid unoccluded brings the sky's radiance around its direction,
// prefiltered to its aperture, and the share of the hemisphere the cones found open,
//   V = sum_j z_j (1 - a_j) / sum_j z_j,
// which the diffuse gather leaves to the sky (gather/trace_anchor_cones.comp). Runs when the voxels or the environment change, over every
// class at once or one interleave class a frame in the viewer, or over the touched voxels (those
// a scrolled clipmap level took in).
#include "lib/voxel_surface.glsl"
#include "lib/cone.glsl"
#include "lib/environment.glsl"
#include "lib/gather_anchors.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_VOXEL_TRACED_SKY_IRRADIANCE) writeonly buffer TracedSky { uvec2 sky_traced_out[]; };
#include "lib/voxel_list.glsl"
#include "lib/lit_box.glsl"

// The voxel's own offsets of its cones in [0, 1)^2: a hash of its coordinates.
vec2 cone_jitter(ivec3 v) {
    uint h = uint(v.x) * 73856093u ^ uint(v.y) * 19349663u ^ uint(v.z) * 83492791u;
    h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
    return vec2(float(h & 0xffffu), float(h >> 16)) / 65536.0;
}

// Cone j of the voxel's set in its tangent frame (z along the normal): z = 1 - (j + u) / count,
// the golden angle apart in azimuth, turned by u'.
vec3 sky_cone(int j, vec2 jitter) {
    float z = 1.0 - (float(j) + jitter.x) / float(SKY_CONE_COUNT);
    float azimuth = 2.0 * PI * (float(j) * 0.381966011 + jitter.y);  // (3 - sqrt 5) / 2 turns apart
    float r = sqrt(max(1.0 - z * z, 0.0));
    return vec3(r * cos(azimuth), r * sin(azimuth), z);
}

// Bit k: level k's voxels whose centres lie in the lit box (lib/lit_box.glsl) take their light
// now, the others keep theirs.
uniform uint lit_levels;

void main() {
    ivec3 v;
    if (!segment_voxel(gl_GlobalInvocationID.x, v)) return;
    if (!in_level_mask(lit_levels, v)) return;
    if (!near_lit_box(voxel_center(v), 0.0)) return;
    uint record = voxel_record(v);
    if (record == NO_RECORD || (gather_anchors[record] & ANCHOR_SELF) == 0u) return;  // empty, or interpolated (GatherPass.fill)
    VoxelSurface s = voxel_surface(v, record, 0);  // side 0 says how many sides there are
    int sides = s.sides;
    for (int side = 0; side < sides; ++side) {  // each side from its own surface
        if (side > 0) s = voxel_surface(v, record, side);
        vec3 irradiance = vec3(0.0);
        float open_share = 0.0;  // V = sum_j z_j (1 - a_j) / sum_j z_j
        bool traced = dot(s.mean_normal, s.mean_normal) > 0.0;  // a surface of this side
        if (traced) {
            vec3 n = normalize(s.mean_normal);
            vec3 start = side_cone_start(s, n, v, sides);
            mat3 frame = tangent_frame(n);
            float tan_half = tan(SKY_CONE_HALF_ANGLE);
            vec2 jitter = cone_jitter(v);
            float cosine_sum = 0.0;
            for (int j = 0; j < SKY_CONE_COUNT; ++j) {
                vec3 local = sky_cone(j, jitter);
                vec3 w = frame * local;
                float opacity = trace_cone(start, n, voxel_level(v), w, tan_half, 1e9, SKY_READING).a;
                float open = local.z * (1.0 - min(opacity, 1.0));  // z_j (1 - a_j)
                irradiance += open * environment_radiance(w, SKY_CONE_HALF_ANGLE);
                open_share += open;
                cosine_sum += local.z;
            }
            irradiance *= PI / cosine_sum;  // E = pi x the cosine-weighted mean radiance
            open_share /= cosine_sum;
        }
        sky_traced_out[side_value(record, side)] = pack_value(traced ? sky_value(irradiance, open_share) : vec4(0.0));
    }
}
