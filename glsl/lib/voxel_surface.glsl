// The resolved surface of each voxel (written by voxelize/resolve_sums.comp): reflectance, mean
// normal, emission, and the point on the surface nearest the voxel centre.
#include "lib/voxel_records.glsl"

layout(std430, binding = SSBO_VOXEL_ALBEDO) readonly buffer VoxelAlbedo { uvec2 voxel_albedo[]; };       // rgb, a = 1
// xyz mean normal, w: opacity (blended surfaces' mean alpha, else 1), negative at side 0 of a
// voxel that has a side 1 (sides_of)
layout(std430, binding = SSBO_VOXEL_NORMAL) readonly buffer VoxelNormal { uvec2 voxel_normal[]; };
layout(std430, binding = SSBO_VOXEL_EMISSION) readonly buffer VoxelEmission { uvec2 voxel_emission[]; }; // rgb, a = surface offset in voxels

// How many sides a voxel has, from its side 0's normal (normal.w < 0: a side 1 too): loops over
// a voxel's sides read side 1 only where it has one.
int sides_of(vec4 side_0_normal) {
    return side_0_normal.w < 0.0 ? 2 : 1;
}

// The normal of side `side` of the voxel at `record` (w: its opacity, negative at side 0 of a
// voxel with two), from side 0's (read already). A loop over a voxel's sides up to sides_of
// rather than an if for side 1: llvmpipe runs an if's body under a lane mask whether or not a
// lane takes it, and a loop ends where no lane has another side.
vec4 side_normal(uint record, int side, vec4 side_0_normal) {
    return side == 0 ? side_0_normal : unpack_value(voxel_normal[side_value(record, side)]);
}

struct VoxelSurface {
    vec3 albedo;       // reflectance (lib/brdf.glsl layered_albedo), averaged over the voxel's fragments
    vec3 mean_normal;  // mean of the fragments' unit normals: its length is their coherence
    vec3 position;     // the voxel centre moved along the normal onto the (mean) surface
    vec3 emission;     // radiance of the front sides, W/(m^2 sr)
    int sides;         // read at side 0: how many sides the voxel has (sides_of)
};

// The surface of covered voxel v, which holds `record`.
// Side `side` of voxel v's surfaces (a zero mean normal: no surface of that side).
VoxelSurface voxel_surface(ivec3 v, uint record, int side) {
    VoxelSurface s;
    uint at = side_value(record, side);
    vec4 emission = unpack_value(voxel_emission[at]);
    s.albedo = unpack_value(voxel_albedo[at]).rgb;
    vec4 normal = unpack_value(voxel_normal[at]);
    s.mean_normal = normal.xyz;
    s.sides = sides_of(normal);
    s.emission = emission.rgb;
    float length_n = length(s.mean_normal);
    // Surface point = centre + n * mean(dot(p_i - centre, n_i)): the centre projected onto a plane.
    s.position = voxel_center(v) + (length_n > 0.0 ? s.mean_normal / length_n * emission.a * voxel_extent(v) : vec3(0.0));
    return s;
}


// The record of the voxel of v's level that holds point p, other than v (NO_RECORD: v itself,
// or a voxel no surface covers).
uint other_record_at(ivec3 v, vec3 p) {
    int level = voxel_level(v);
    ivec3 u = level_voxel(ivec3(floor(level_uvw(p, level) * float(voxel_grid))), level);
    return u == v ? NO_RECORD : neighbour_record(v, u);
}

// Whether the first surface behind a side's surface point, within BACKING_REACH voxels against
// its normal n, faces the other way: the far face of a slab whose faces fall in other voxels.
bool backed_by_neighbour(VoxelSurface s, vec3 n, ivec3 v) {
    for (float k = 1.0; k <= BACKING_REACH; k += 1.0) {
        uint record = other_record_at(v, s.position - k * voxel_extent(v) * n);
        if (record == NO_RECORD) continue;
        vec4 normal = unpack_value(voxel_normal[side_value(record, 0)]);
        for (int side = 0; side < sides_of(normal); ++side) {
            vec3 m = side_normal(record, side, normal).xyz;
            if (dot(m, n) < -SIDES_APART * length(m)) return true;
        }
        return false;
    }
    return false;
}

// Where the cones a side traces itself start from: its surface point, in a voxel with two
// sides (`sides`) or backed by a neighbour (backed_by_neighbour), whose near cells hold the
// other face's light, moved further along its normal n by up to TWO_SIDED_START voxels, whole
// voxels at a time while they hold no other surface (a curtain's fold above a floor starts over
// the floor, not under it).
vec3 side_cone_start(VoxelSurface s, vec3 n, ivec3 v, int sides) {
    if (sides < 2 && !backed_by_neighbour(s, n, v)) return s.position;
    float extent = voxel_extent(v);
    float free_voxels = 0.0;
    for (float k = 1.0; k <= TWO_SIDED_START; k += 1.0) {
        if (other_record_at(v, s.position + k * extent * n) != NO_RECORD) break;
        free_voxels = k;
    }
    return s.position + free_voxels * extent * n;
}
