// The voxel grid: voxel_levels levels of voxel_grid^3 voxels, level k a cube at
// level_region_min[k] of voxels level_voxel_size[k] wide (a single grid is one level; a
// clipmap's levels nest, each twice as coarse as the one inside it). The levels are stacked
// along z in voxel space: voxel (x, y, z) of level k is v = (x, y, z + k N), so that lists,
// records and cells address every level alike.
#include "engine_constants.glsl"
uniform int voxel_grid;       // N voxels per side of a level
uniform int voxel_levels;     // L levels, 1..MAX_VOXEL_LEVELS
uniform vec3 level_region_min[MAX_VOXEL_LEVELS];
uniform float level_voxel_size[MAX_VOXEL_LEVELS];
uniform float voxel_size;     // the finest level's voxel size: the unit of the cones' footprints
uniform bool voxel_emitters;  // whether any surface emits (the emission volume and the emitters' light are built)
uniform bool voxel_sky;       // whether the scene has an environment (the sky's light is built)

// The level voxel v belongs to.
int voxel_level(ivec3 v) {
    return v.z / voxel_grid;
}

// Voxel v of the stack from its coordinates `local` within level `level`.
ivec3 level_voxel(ivec3 local, int level) {
    return ivec3(local.xy, local.z + level * voxel_grid);
}

// Whether voxel v lies in one of the levels of `mask` (bit k: level k).
bool in_level_mask(uint mask, ivec3 v) {
    return (mask & (1u << voxel_level(v))) != 0u;
}

// Whether v lies in the stack of levels.
bool inside_levels(ivec3 v) {
    return all(greaterThanEqual(v, ivec3(0))) && all(lessThan(v, ivec3(voxel_grid, voxel_grid, voxel_levels * voxel_grid)));
}

// World position -> texture coordinates in [0,1]^3 of a level's cube (voxel i covers
// [i, i+1) / N).
vec3 level_uvw(vec3 p, int level) {
    return (p - level_region_min[level]) / (level_voxel_size[level] * float(voxel_grid));
}

// How deep p lies inside level `level`'s cube, in the level's voxels (negative outside).
float level_depth(vec3 p, int level) {
    vec3 uvw = level_uvw(p, level);
    vec3 inside = min(uvw, 1.0 - uvw) * float(voxel_grid);
    return min(min(inside.x, inside.y), inside.z);
}

// How far a lookup at some level reaches from its point, in that level's voxels: `distance`
// (world) plus `voxels` of the level.
float level_reach(int level, float distance, float voxels) {
    return distance / level_voxel_size[level] + voxels;
}

// The finest level from `first` up whose cube holds a lookup at p that reaches `distance` plus
// `voxels` of the level's own (level_reach), else the coarsest. Levels nest: the finer ones
// hold less.
int holding_level(vec3 p, int first, float distance, float voxels) {
    int level = first;
    while (level < voxel_levels - 1 && level_depth(p, level) < level_reach(level, distance, voxels)) ++level;
    return level;
}

// The share a lookup at p reaching `reach` voxels of level `level` takes from that level; the
// next coarser level takes the rest. It falls from 1 to 0 over the LEVEL_BLEND_VOXELS before the
// lookup would reach past the border (the coarsest level takes all: nothing lies beyond it).
float level_share(vec3 p, int level, float reach) {
    if (level == voxel_levels - 1) return 1.0;
    return clamp((level_depth(p, level) - reach) / LEVEL_BLEND_VOXELS, 0.0, 1.0);
}

// The finest level that holds a surface point p with the 8 voxels around it (its voxels'
// light is read there and its cones start there).
int surface_level(vec3 p) {
    return holding_level(p, 0, 0.0, 1.0);
}

// The side of voxel v.
float voxel_extent(ivec3 v) {
    return level_voxel_size[voxel_level(v)];
}

// Centre of voxel v in world space.
vec3 voxel_center(ivec3 v) {
    int level = voxel_level(v);
    return level_region_min[level] + (vec3(v.xy, v.z - level * voxel_grid) + 0.5) * level_voxel_size[level];
}

// Corner k (0..7, x fastest) of a cube of 2 x 2 x 2 cells: the children of a mip cell, or the
// voxels a trilinear lookup reads.
ivec3 corner_offset(int k) {
    return ivec3(k & 1, (k >> 1) & 1, k >> 2);
}

// The 8 voxels a trilinear lookup at uvw (within a level: level_uvw) reads: voxel k is
// first + corner_offset(k) in the level's own coordinates, and t the fraction of the way from
// first's centre to the next voxel's along each axis.
struct TrilinearVoxels {
    ivec3 first;
    vec3 t;
};

TrilinearVoxels trilinear_voxels(vec3 uvw) {
    vec3 c = uvw * float(voxel_grid) - 0.5;  // in voxels, from the voxels' centres
    TrilinearVoxels lookup;
    lookup.first = ivec3(floor(c));
    lookup.t = c - vec3(lookup.first);
    return lookup;
}

// The weight the trilinear lookup gives voxel k: the product of its shares along the axes.
float trilinear_weight(TrilinearVoxels lookup, int k) {
    vec3 share = mix(1.0 - lookup.t, lookup.t, vec3(corner_offset(k)));
    return share.x * share.y * share.z;
}

// Index of cell c of the stack of levels at a mip level whose levels are `side` cells wide, in a
// buffer of one entry per cell of every level (x fastest, so level after level).
uint grid_index(ivec3 c, int side) {
    return uint(c.x) + uint(side) * (uint(c.y) + uint(side) * uint(c.z));
}

// Index of voxel v in the per-voxel buffers (the records' index).
uint voxel_index(ivec3 v) {
    return grid_index(v, voxel_grid);
}

// Cones read VOXEL_FACES one-sided views of the radiance, one per face direction (+x, -x, +y,
// -y, +z, -z): view f holds the surfaces that face along f, i.e. those a cone travelling
// against f can see. Surfaces are one-sided (they face into the room, or out of a solid).
// The views are stacked along z in one volume, each a stack of the levels: at a mip level whose
// levels are `side` cells wide, cell v of view f is texel (v.x, v.y, v.z + f L side).
ivec3 face_texel(ivec3 v, int face, int side) {
    return ivec3(v.xy, v.z + face * voxel_levels * side);
}

// Texture coordinates in a volume of `slabs` stacks of the levels along z (the face views:
// VOXEL_FACES; the emission volume: 1) of a lookup at uvw within level `level`'s cube in slab
// `slab`, at a mip level whose levels are `side` texels wide: the depth coordinate is clamped to
// the level's own texels, so a lookup filters within its view and level.
vec3 stacked_uvw(vec3 uvw, int level, int slab, int slabs, float side) {
    float w = clamp(uvw.z, 0.5 / side, 1.0 - 0.5 / side);
    return vec3(uvw.xy, (float(slab * voxel_levels + level) + w) / float(slabs * voxel_levels));
}

// The axis along which v is longest (the first of equals).
int dominant_axis(vec3 v) {
    vec3 a = abs(v);
    return a.x >= a.y ? (a.x >= a.z ? 0 : 2) : (a.y >= a.z ? 1 : 2);
}

// The face view a surface with normal n belongs to: its dominant axis k and sign, 2k (+) or
// 2k + 1 (-).
int facing_face(vec3 n) {
    int axis = dominant_axis(n);
    return 2 * axis + int(n[axis] < 0.0);
}

// How much a voxel's values (its gather, the emitters' light at it) stand for those at a
// surface with unit normal n: max(0, n . n_v / |n_v|)^FACING_EXPONENT times the coherence |n_v|
// of its mean normal n_v (nonzero), so voxels of mixed surfaces count less.
float facing_weight(vec3 n, vec3 n_v) {
    float coherence = length(n_v);
    return pow(max(dot(n, n_v) / coherence, 0.0), FACING_EXPONENT) * coherence;
}

// Fraction of a voxel's cross-section, seen against each face, that its surfaces cover: the
// faces 2k (surfaces facing +k) in `plus`, 2k + 1 (facing -k) in `minus`. A plane with unit
// normal n inside a voxel covers |n_k| / max_j |n_j| of the face perpendicular to axis k, and
// only when it faces that way. The mean normal's length is the coherence of the surfaces in
// the voxel: spread normals (edges, thin two-sided parts) cover every face.
struct FaceCoverage {
    vec3 plus;
    vec3 minus;
};

FaceCoverage face_coverages(vec3 mean_normal) {
    float coherence = min(length(mean_normal), 1.0);
    if (coherence <= 0.0) return FaceCoverage(vec3(1.0), vec3(1.0));
    vec3 n = mean_normal / length(mean_normal);
    float scale = coherence / max(max(abs(n.x), abs(n.y)), abs(n.z));
    return FaceCoverage(scale * max(n, 0.0) + (1.0 - coherence), scale * max(-n, 0.0) + (1.0 - coherence));
}

float face_coverage(FaceCoverage c, int face) {
    return (face & 1) == 0 ? c.plus[face >> 1] : c.minus[face >> 1];
}

// Voxel coordinates packed into one uint for the voxel lists (N <= 2^VOXEL_PACK_BITS; z, which
// spans the levels, takes the remaining bits); NO_VOXEL is the word no voxel has.

uint pack_voxel(ivec3 v) {
    return uint(v.x) | (uint(v.y) << VOXEL_PACK_BITS) | (uint(v.z) << (2 * VOXEL_PACK_BITS));
}

ivec3 unpack_voxel(uint bits) {
    uint mask = (1u << VOXEL_PACK_BITS) - 1u;
    return ivec3(bits & mask, (bits >> VOXEL_PACK_BITS) & mask, bits >> (2 * VOXEL_PACK_BITS));
}
