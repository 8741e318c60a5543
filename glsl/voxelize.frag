#version 450 core
// Voxelization, fragment stage: one fragment = one surface sample in one voxel. Its diffuse
// albedo and emission (the material's factors times its textures, sampled at the mip level of
// a voxel's footprint), unit normal, offset along the normal from the voxel centre are added to
// the voxel's fixed-point sums with atomics, with a fragment count (lib/voxel_sums.glsl). The
// first fragment in a voxel flags it and lists it as touched. An update of part of the scene
// runs in two passes: `mark_only` flags the voxels the changed objects cover (before and
// after the change), then `touched_only` re-adds every object's fragments in those voxels
// alone; a full voxelization runs neither restriction.
#include "lib/voxel.glsl"
#include "lib/voxel_sums.glsl"
#include "lib/material.glsl"

in vec3 gs_position;
in vec3 gs_normal;
in vec2 gs_texcoord;
flat in vec4 gs_pixel_bounds;
uniform bool mark_only;
uniform bool touched_only;
layout(std430, binding = SSBO_TOUCHED) buffer TouchedVoxels { uint touched_count; uint touched[]; };

uint unit_fixed(float x) {  // two's complement of round(x * VOXEL_UNIT_SCALE), |x| <= 1
    return uint(int(round(clamp(x, -1.0, 1.0) * VOXEL_UNIT_SCALE)));
}

// Adds emission to a 64-bit sum: the low word, and its carry word when the low word wraps.
void add_emission(uint i, uint low_channel, uint carry_channel, float radiance) {
    uint x = uint(clamp(radiance, 0.0, VOXEL_MAX_EMISSION) * VOXEL_EMISSION_SCALE + 0.5);
    if (x == 0u) return;
    uint before = atomicAdd(voxel_sums[low_channel].value[i], x);
    if (before + x < before) atomicAdd(voxel_sums[carry_channel].value[i], 1u);
}

void main() {
    MaterialSample m = sample_material(gs_texcoord);  // before any discard: derivatives need the neighbours
    if (cut_out(m.alpha)) discard;
    // Dilation grows the triangle at acute corners; clip it to its own bounding box.
    vec2 pixel = gl_FragCoord.xy;
    if (any(lessThan(pixel, gs_pixel_bounds.xy)) || any(greaterThan(pixel, gs_pixel_bounds.zw))) discard;
    ivec3 voxel = ivec3(floor(voxel_uvw(gs_position) * float(voxel_grid)));
    if (any(lessThan(voxel, ivec3(0))) || any(greaterThanEqual(voxel, ivec3(voxel_grid)))) discard;
    uint i = voxel_index(voxel);

    if (touched_only) {
        if ((voxel_sums[SUM_COUNT].value[i] & TOUCHED_FLAG) == 0u) discard;
    } else {
        uint flags = atomicOr(voxel_sums[SUM_COUNT].value[i], TOUCHED_FLAG);
        if ((flags & TOUCHED_FLAG) == 0u) touched[atomicAdd(touched_count, 1u)] = pack_voxel(voxel);
        if (mark_only) return;
    }
    uint earlier_fragments = atomicAdd(voxel_sums[SUM_COUNT].value[i], 1u) & COUNT_MASK;
    if (earlier_fragments >= VOXEL_MAX_FRAGMENTS) return;  // headroom of the signed sums

    vec3 n = normalize(gs_normal);
    vec3 diffuse_albedo = (1.0 - m.metalness) * m.albedo;
    float offset = dot(gs_position - voxel_center(voxel), n) / voxel_size;  // in [-0.87, 0.87]
    atomicAdd(voxel_sums[SUM_ALBEDO_R].value[i], unit_fixed(diffuse_albedo.r));
    atomicAdd(voxel_sums[SUM_ALBEDO_G].value[i], unit_fixed(diffuse_albedo.g));
    atomicAdd(voxel_sums[SUM_ALBEDO_B].value[i], unit_fixed(diffuse_albedo.b));
    atomicAdd(voxel_sums[SUM_NORMAL_X].value[i], unit_fixed(n.x));
    atomicAdd(voxel_sums[SUM_NORMAL_Y].value[i], unit_fixed(n.y));
    atomicAdd(voxel_sums[SUM_NORMAL_Z].value[i], unit_fixed(n.z));
    atomicAdd(voxel_sums[SUM_OFFSET].value[i], unit_fixed(offset));
    add_emission(i, SUM_EMISSION_R, SUM_EMISSION_CARRY_R, m.emission.r);
    add_emission(i, SUM_EMISSION_G, SUM_EMISSION_CARRY_G, m.emission.g);
    add_emission(i, SUM_EMISSION_B, SUM_EMISSION_CARRY_B, m.emission.b);
}
