#version 450 core
// Voxelization, fragment stage: one fragment = one surface sample in one voxel. Its reflectance
// (the layered model's hemispherical albedo, lib/brdf.glsl) and emission (the material's
// factors times its textures, sampled at the mip level of a voxel's footprint), unit normal,
// offset along the normal from the voxel centre and opacity (its alpha times the share of the
// voxel's face the triangle covers: pixel_coverage) are added to the voxel's fixed-point sums
// with atomics, with a fragment count (lib/voxel_sums.glsl).
//
// Surfaces that share a voxel and face the same way (a lamp under a ceiling, a picture on a
// wall, a rug on a floor) hide one another: seen from their front, only the front-most shows.
// So per voxel and facing direction (the dominant axis of the normal, with its sign) only the
// front-most layer is summed: VOXELIZE_FRONT records the largest offset along the normal
// (atomicMax, order-independent), VOXELIZE_ADD adds the fragments within LAYER_TOLERANCE of it
// (a plane has one offset in a voxel; a curved surface, about one).
//
// Stages: VOXELIZE_MARK flags and lists as touched the voxels the changed objects cover (a
// partial update's before and after the change; every object for a full voxelization);
// VOXELIZE_FRONT, then VOXELIZE_ADD, over every object reaching them, at the touched voxels of
// the chunk being summed (lib/voxel_sums.glsl).
#include "lib/voxel.glsl"
#include "lib/voxel_sums.glsl"
#include "lib/material.glsl"
#include "lib/brdf.glsl"

#define LAYER_TOLERANCE 0.125  // voxels
#define BOUNDARY_BIAS 1e-3     // voxels

in vec3 gs_position;
in vec3 gs_normal;
#ifdef VERTEX_EXTRAS
in vec3 gs_color;
in vec4 gs_map_coordinates01;
in vec4 gs_map_coordinates23;
#else
in vec2 gs_texcoord;
const vec3 gs_color = vec3(1.0);
#endif
flat in vec4 gs_pixel_bounds;
flat in vec3 gs_edges[3];
flat in uint gs_material;     // NO_MATERIAL: a held draw, marked as it is not cut out
// The job's voxels [min, max) in its level's own coordinates (the whole cube, or the slab a
// scrolled level took in); w: the level.
flat in ivec4 gs_voxels_min;
flat in ivec3 gs_voxels_max;
uniform int stage;

// The offset of a surface along its normal from the voxel centre, in voxels, as an ordered key.
uint layer_key(float offset) {
    return uint((clamp(offset, -1.0, 1.0) + 1.0) * 32767.0);
}

// Whether point p lies inside edge line e (e.xy . p + e.z > 0); a point on the line counts for
// one of the two triangles sharing it, the one whose inside the line's normal points to first
// along x, then y (a top-left rule), so that triangles sharing an edge cover it once.
bool inside_edge(vec3 e, vec3 p) {
    float d = dot(e, p);
    return d > 0.0 || (d == 0.0 && (e.x > 0.0 || (e.x == 0.0 && e.y > 0.0)));
}

// The share of the fragment's pixel (a voxel's face) the undilated triangle covers: the
// share of COVERAGE_SAMPLES^2 points spread evenly over the pixel inside its three edges.
#define COVERAGE_SAMPLES 4
float pixel_coverage(vec2 pixel_centre) {
    int inside = 0;
    for (int i = 0; i < COVERAGE_SAMPLES; ++i)
        for (int j = 0; j < COVERAGE_SAMPLES; ++j) {
            vec2 sample_pixels = pixel_centre + (vec2(i, j) + 0.5) / float(COVERAGE_SAMPLES) - 0.5;
            vec3 p = vec3(sample_pixels * (2.0 / float(voxel_grid)) - 1.0, 1.0);  // in NDC, as the edges
            if (inside_edge(gs_edges[0], p) && inside_edge(gs_edges[1], p) && inside_edge(gs_edges[2], p)) ++inside;
        }
    return float(inside) / float(COVERAGE_SAMPLES * COVERAGE_SAMPLES);
}

uint unit_fixed(float x) {  // two's complement of round(x * VOXEL_UNIT_SCALE), |x| <= 1
    return uint(int(round(clamp(x, -1.0, 1.0) * VOXEL_UNIT_SCALE)));
}

// Adds emission to a 64-bit sum: the low word, and its carry word when the low word wraps.
void add_emission(int slot, int orientation, int low_channel, int carry_channel, float radiance) {
    uint x = uint(clamp(radiance, 0.0, VOXEL_MAX_EMISSION) * VOXEL_EMISSION_SCALE + 0.5);
    if (x == 0u) return;
    uint before = atomicAdd(voxel_sums[sum_entry(slot, orientation, low_channel)], x);
    if (before + x < before) atomicAdd(voxel_sums[sum_entry(slot, orientation, carry_channel)], 1u);
}

// A fragment of normal n and offset `offset` along it into voxel slot `slot`: its front-layer
// key and its count (VOXELIZE_FRONT), then, where it lies in the front layer of its facing, its
// sums.
void add_fragment(int slot, vec3 n, float offset, MaterialSample m, vec3 emission, bool double_sided, float coverage) {
    uint key = key_entry(slot, facing_face(n));
    if (stage == VOXELIZE_FRONT) {
        atomicMax(front_keys[key], layer_key(offset));
        atomicAdd(front_keys[count_entry(slot, facing_face(n))], 1u);
        return;
    }
    if (layer_key(offset + LAYER_TOLERANCE) < front_keys[key]) return;  // behind the front layer

    // Summed apart by orientation: with or against the voxel's most common facing.
    int orientation = fragment_orientation(slot, n);
    uint earlier_fragments = atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_COUNT)], 1u);
    if (earlier_fragments >= VOXEL_MAX_FRAGMENTS) return;  // headroom of the signed sums
    // A voxel keeps no direction, so what the specular layer reflects bounces on as a Lambertian
    // lobe: the reflectance is the layered model's hemispherical albedo (a gold sphere passes its
    // light on instead of absorbing it).
    vec3 reflectance = layered_albedo(m.albedo, m.roughness, m.metalness, m.dielectric_f0);
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_ALBEDO_R)], unit_fixed(reflectance.r));
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_ALBEDO_G)], unit_fixed(reflectance.g));
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_ALBEDO_B)], unit_fixed(reflectance.b));
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_NORMAL_X)], unit_fixed(n.x));
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_NORMAL_Y)], unit_fixed(n.y));
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_NORMAL_Z)], unit_fixed(n.z));
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_OFFSET)], unit_fixed(offset));
    // A blended surface covers alpha of what lies behind it; every other one all of it.
    atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_OPACITY)], unit_fixed(coverage * (m.alpha_cutoff == ALPHA_BLENDED ? m.alpha : 1.0)));
    add_emission(slot, orientation, SUM_EMISSION_R, SUM_EMISSION_CARRY_R, emission.r);
    add_emission(slot, orientation, SUM_EMISSION_G, SUM_EMISSION_CARRY_G, emission.g);
    add_emission(slot, orientation, SUM_EMISSION_B, SUM_EMISSION_CARRY_B, emission.b);
    if (double_sided) atomicAdd(voxel_sums[sum_entry(slot, orientation, SUM_DOUBLE_SIDED)], 1u);
}

void main() {
    // Marking needs the material only where it cuts out (uniform control flow: the derivatives
    // of the lookups before any discard still have their neighbours).
    MaterialSample m;
    if (stage != VOXELIZE_MARK || (gs_material != NO_MATERIAL && alpha_tested(gs_material))) {
#ifdef VERTEX_EXTRAS
        MapCoordinates coordinates = MapCoordinates(gs_map_coordinates01, gs_map_coordinates23);
#else
        MapCoordinates coordinates = same_coordinates(gs_texcoord);
#endif
        m = sample_material(gs_material, coordinates, gs_color);
        if (cut_out(m)) discard;
    }
    int voxelize_level = gs_voxels_min.w;
    // Dilation grows the triangle at acute corners; clip it to its own bounding box.
    vec2 pixel = gl_FragCoord.xy;
    if (any(lessThan(pixel, gs_pixel_bounds.xy)) || any(greaterThan(pixel, gs_pixel_bounds.zw))) discard;
    // A surface on a voxel boundary goes to the voxel behind it, not to whichever side the
    // rounding of the level's placement picks: a level keeps the same voxels wherever it lies.
    vec3 behind = gs_position - normalize(gs_normal) * (BOUNDARY_BIAS * level_voxel_size[voxelize_level]);
    ivec3 local = ivec3(floor(level_uvw(behind, voxelize_level) * float(voxel_grid)));
    if (any(lessThan(local, gs_voxels_min.xyz)) || any(greaterThanEqual(local, gs_voxels_max))) discard;
    ivec3 voxel = level_voxel(local, voxelize_level);
    if (stage == VOXELIZE_MARK) {
        touch_voxel(voxel);
        return;
    }
    int slot = sum_slot(voxel);
    if (slot < 0) discard;
    vec3 n = normalize(gs_normal);
    float offset = dot(gs_position - voxel_center(voxel), n) / voxel_extent(voxel);  // in [-0.87, 0.87]
    // A double-sided material's surface is seen from both sides: its fragment adds its back,
    // facing the other way, as a surface of its own (which does not emit).
    bool double_sided = gs_material != NO_MATERIAL && materials[gs_material].sides.x != 0u;
    float coverage = pixel_coverage(gl_FragCoord.xy);
    add_fragment(slot, n, offset, m, m.emission, double_sided, coverage);
    if (double_sided) add_fragment(slot, -n, -offset, m, vec3(0.0), true, coverage);
}
