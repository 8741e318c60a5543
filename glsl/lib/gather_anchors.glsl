// The voxels that trace the diffuse gather (the anchors) and the ones that take it from them.
// A surface's gather varies slowly along it, so the voxels at even coordinates along the two
// axes across their facing (1 in 4 of a plane's) trace the cones, and the others interpolate
// the anchors around them: bilinearly along the surface, and weighted by how alike the
// surfaces face, as the image interpolates the voxels (cone_trace/shade_pixels.frag). A voxel with too few
// anchors of a like facing around it (a thin part, an edge) is an anchor too. A clipmap level's
// voxels beneath the finer level inside it are none of these: the finer voxels that tile each
// hold the same surfaces in more detail, and it takes their mean gather
// (gather/take_finer_gather.comp).
//
// gather/find_anchors.comp writes the anchors of each covered voxel (GATHER_ANCHORS, a word per
// record: lib/voxel_records.glsl): the bit ANCHOR_SELF when it traces the gather itself,
// ANCHOR_FINER when it lies beneath a finer level, or else the bit k of each neighbour k
// (`neighbour`, within ANCHOR_NEIGHBOURS) that is an anchor it takes its gather from, and its
// facing from bit ANCHOR_FACING_SHIFT (what the class sort reads: voxel_facing). A voxel's
// anchors depend on it, its neighbours and where the finer level lies only: after a
// voxelization, gather/mark_stale_anchors.comp marks those around the voxels it touched
// ANCHOR_STALE, and only those are found again; after a scroll, those of the scrolled levels
// and of the next coarser ones (GatherPass.find_anchors). The lattice is side 0's: an anchor
// traces each of its sides' gathers, a voxel that interpolates takes each side's from the
// sides of its anchors that face alike (side_anchor_weight), and a voxel beneath a finer level
// takes both from the finer voxels.
#include "lib/voxel_surface.glsl"

layout(std430, binding = SSBO_GATHER_ANCHORS) buffer GatherAnchors { uint gather_anchors[]; };

// Voxels whose surface reflects no light gather nothing (a covered voxel's side, side_value,
// and its mean normal n).
bool reflects_light(uint at, vec3 n) {  // at: a record's side (side_value)
    vec4 albedo = unpack_value(voxel_albedo[at]);
    return albedo.a > 0.0 && any(greaterThan(albedo.rgb, vec3(0.0))) && dot(n, n) > 1e-6;
}

// The first of the 8 voxels of level voxel_level(v) - 1 that tile voxel v (in that level's own
// coordinates): the levels' corners lie on whole voxels of their own size, so v's corner lies
// on a finer voxel's.
ivec3 first_finer_voxel(ivec3 v) {
    int level = voxel_level(v);
    vec3 corner = voxel_center(v) - 0.5 * level_voxel_size[level];
    return ivec3(round((corner - level_region_min[level - 1]) / level_voxel_size[level - 1]));
}

// Whether voxel v lies beneath a finer level: a level above the finest whose voxel lies within
// the finer level's cube, so that the 8 finer voxels tiling it all exist.
bool beneath_finer_level(ivec3 v) {
    if (voxel_level(v) == 0) return false;
    ivec3 first = first_finer_voxel(v);
    return all(greaterThanEqual(first, ivec3(0))) && all(lessThanEqual(first, ivec3(voxel_grid - 2)));
}

// The axes along a surface across `axis` (its normal's dominant one): the two others.
ivec2 tangent_axes(int axis) {
    return ivec2((axis + 1) % 3, (axis + 2) % 3);
}

// A covered voxel's facing (the class sort's buckets, CLASS_FACINGS): the face view its mean
// normal n belongs to, or CLASS_FACINGS - 1 where n is zero.
int voxel_facing(vec3 n) {
    return dot(n, n) > 0.0 ? facing_face(n) : CLASS_FACINGS - 1;
}

// Whether a voxel with mean normal n lies on the anchors' lattice: even along its surface.
bool on_anchor_lattice(ivec3 v, vec3 n) {
    ivec2 t = tangent_axes(dominant_axis(n));
    return ((v[t.x] | v[t.y]) & 1) == 0;
}

// Interleave class of a voxel (of `facing`: voxel_facing) for the progressive bounce: the
// position of its level-1 cell (2x2x2 voxels) in the 2x2 block of cells along its surface,
// then the cell's layer. A class spreads over the surfaces evenly (its anchors are a quarter of a plane's, 4
// voxels apart), and a cell holds one class unless surfaces of several facings meet in it, so
// that the face views' level 1 changes in the cells of the class composed (gather/sort_class_cells.comp).
int voxel_class(ivec3 v, int facing, int interleave) {
    ivec3 cell = v >> 1;
    int axis = facing < CLASS_FACINGS - 1 ? facing >> 1 : 0;  // a zero normal's dominant axis is x
    ivec2 t = tangent_axes(axis);
    return ((cell[t.x] & 1) | ((cell[t.y] & 1) << 1) | ((cell[axis] & 1) << 2)) % interleave;
}

// The k-th of the 26 neighbours of v (k < 26).
ivec3 neighbour(ivec3 v, int k) {
    int i = k < 13 ? k : k + 1;  // skip the centre, 13
    return v + ivec3(i % 3, (i / 3) % 3, i / 9) - 1;
}

// How much an anchor with mean normal n_u at neighbour u stands for voxel v with unit normal n:
// a tent two voxels wide per axis (0.5 for a neighbour along an axis, 0.25 across a diagonal)
// times how alike they face (facing_weight, as the image weighs the voxels).
float anchor_weight(ivec3 v, vec3 n, ivec3 u, vec3 n_u) {
    vec3 d = abs(vec3(u - v));
    float tent = (1.0 - 0.5 * d.x) * (1.0 - 0.5 * d.y) * (1.0 - 0.5 * d.z);
    return tent * facing_weight(n, n_u);
}

// The mean normals of the sides of the covered voxel at `record` that reflect light, zero for
// a side that reflects none or that it lacks, from its side 0's normal `normal` (read already).
// `one_side_reflects`: a one-sided voxel is known to reflect light (an anchor, or a voxel with
// anchors recorded), so its reflectance need not be read.
void reflecting_sides(uint record, vec4 normal, bool one_side_reflects, out vec3 front, out vec3 back) {
    front = normal.xyz;
    back = vec3(0.0);
    if (sides_of(normal) > 1) {
        vec3 n_1 = unpack_value(voxel_normal[side_value(record, 1)]).xyz;
        if (reflects_light(side_value(record, 1), n_1)) back = n_1;
        if (!reflects_light(side_value(record, 0), front)) front = vec3(0.0);
    } else if (!one_side_reflects && !reflects_light(side_value(record, 0), front)) {
        front = vec3(0.0);
    }
}

// How much an anchor's side with mean normal n_u (zero: none) at neighbour u stands for a side
// of voxel v with unit normal n: anchor_weight where it faces n's way, else 0.
float side_anchor_weight(ivec3 v, vec3 n, ivec3 u, vec3 n_u) {
    return dot(n, n_u) > 0.0 ? anchor_weight(v, n, u, n_u) : 0.0;
}
