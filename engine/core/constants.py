"""Constants shared by the host and the shaders, defined once.

`glsl_header()` turns them into the virtual include "engine_constants.glsl", so a
binding point, a fixed-point scale or a cone table can never differ between Python and GLSL.

Binding budgets are those of the least generous OpenGL 4.5 drivers: at most 8 image units
(NVIDIA's limit) and at most 16 storage blocks per shader stage.
"""
import functools
import math

import numpy as np

# A module-level constant annotated with one of these goes into GLSL as a #define of that type
# (glsl_header): written once, here.
GLSL_INT, GLSL_UINT, GLSL_FLOAT = "int", "uint", "float"

# Texture units (sampler bindings).
TEXTURE_UNIT = {
    "GBUF_POSITION": 0,
    "GBUF_NORMAL": 1,
    "GBUF_ALBEDO": 2,
    "GBUF_EMISSION": 3,
    "SHADOW_ATLAS": 4,
    "BLEND_SUMS": 5,        # blended surfaces' weighted sums (rgb: sum w a C, a: sum w a; transparent/)
    "BLEND_COVERAGE": 6,    # the share of the opaque image they cover, 1 - prod (1 - a)
    "VOXEL_FACES": 11,      # the face views cones read (+x, -x, +y, -y, +z, -z) from mip level 1 up, stacked along z
    "HISTORY": 8,           # temporal anti-aliasing's image of the frames before (temporal/)
    "HISTORY_DISTANCE": 9,  # and the distance from the camera of what each of its pixels saw (0: the sky)
    "GBUF_PREVIOUS": 10,    # where each pixel's surface point was at the frame before (the G-buffer's motion)
    "HDR_INPUT": 12,
    "DIRECT_LIGHT": 13,
    "VOXEL_INSPECT": 14,    # the volume a voxel view or a readback reads
    "VOXEL_CONE_EMISSION": 15,    # emission (rgb) and coverage (a) from mip level 1 up: what specular cones add
    "ENVIRONMENT": 17,      # the sky's radiance, equirectangular, mipmapped (glsl/lib/environment.glsl)
    "MATERIAL_TEXTURES": 18,  # the materials' textures: MATERIAL_TEXTURE_ARRAYS texture arrays from here on
}
# The materials' textures are grouped by size, colour encoding and wrapping into this many 2D
# texture arrays, bound once for every draw (engine/gpu/scene_buffers.py MaterialTextures; units 18..29:
# unit 31 is moderngl's own).
MATERIAL_TEXTURE_ARRAYS: GLSL_INT = 12

# Image units. Each program binds at most 8 images, at units 0..7.
IMAGE_UNIT = {
    "FACES_OUT": 0,
    "CONE_EMISSION_OUT": 4,
    "INSPECT_OUT": 0,       # a dense volume made from a record array, for inspection
    "IMAGE_OUT": 0,         # a screen target a compute pass adds to
    "AVERAGE_OUT": 0,       # the mean of a frame's jittered samples (average_samples/)
    "HISTORY_OUT": 0,       # temporal/: the history of the frames shown, and
    "HISTORY_DISTANCE_OUT": 1,  # the distance from the camera each of its pixels saw
    "SPECULAR_IN": 1,       # the specular cones' incoming radiance at the anchor pixels (half resolution)
    "DIFFUSE_IN": 2,        # the diffuse cones' gather at the anchor pixels that traced them (a = 1; half resolution)
}

# A covered voxel keeps its surfaces by orientation, in up to VOXEL_SIDES sides: side 0 the
# fragments of the orientation most of them have (with or against the voxel's most common
# facing: lib/voxel_sums.glsl fragment_orientation), side 1 those of the opposite one where
# they face apart (the back of a sheet, the far face of a slab thinner than a voxel). Each side
# has its own surface and light: a value per record and side.
VOXEL_SIDES: GLSL_INT = 2
# The orientations of a voxel's fragments make two sides where their mean normals face apart,
# cos(angle between them) < -SIDES_APART; else one side holds them all (a floor meeting a wall).
SIDES_APART: GLSL_FLOAT = 0.5
# ... and where the plane of orientation 0 lies in front of orientation 1's by more than
# SIDES_GAP voxels (glsl/voxelize/resolve_sums.comp): ten times the rounding that parts
# coincident faces (a box standing on a floor: below 0.001 voxels on the Cornell box's grids),
# so that sheets a few millimetres apart keep their two faces on a coarse grid (two sheets 1 cm
# apart are 0.04 of a voxel of a 128^3 grid over a 30 m courtyard).
SIDES_GAP: GLSL_FLOAT = 0.01
# The cones a side of a two-sided voxel traces itself (its gather, the sky's light at it) start up to
# this many voxels further along its normal (short of any other surface there): the cells around the voxel hold its other side's
# light, which cones starting nearer read as if in front (the thin sheet's reference scene:
# 2 voxels left its camera side 2.7x bright at 128^3, 4 within 1.4x).
TWO_SIDED_START: GLSL_FLOAT = 4.0
# So do a one-sided voxel's where the first surface within BACKING_REACH voxels behind it faces
# the other way (lib/voxel_surface.glsl backed_by_neighbour): a slab's faces in neighbouring
# voxels, whose coarse cells hold both (the thin slab's camera face 4.8x bright at 128^3 from
# its surface, 1.35x from 4 voxels; at 256^3, its faces 2.6 voxels apart, 4.3x with a reach of
# 1 voxel, 1.76x with 2; Sponza's indirect light 0.847 without, 0.849 and 0.852 with 1 and 2).
BACKING_REACH: GLSL_FLOAT = 2.0
# A voxel side's surface point is the mean of its fragments, which lies behind some of them
# where the surface is not flat (a curtain's folds, a capital): its shadow lookups are moved this
# many voxels further along its normal, over the shadow maps' own offset of a few texels.
VOXEL_SHADOW_LIFT: GLSL_FLOAT = 0.5
# Per-voxel fixed-point sums the voxelizer accumulates with atomics, a record of these channels
# per touched voxel and orientation (lib/voxel_sums.glsl). Normal and offset sums are signed
# (two's complement). Emission is summed in 64 bits: the low word, and a carry word incremented
# on overflow.
VOXEL_SUM_CHANNELS = ("COUNT", "ALBEDO_R", "ALBEDO_G", "ALBEDO_B", "NORMAL_X", "NORMAL_Y", "NORMAL_Z", "OFFSET",
                      "EMISSION_R", "EMISSION_G", "EMISSION_B", "EMISSION_CARRY_R", "EMISSION_CARRY_G",
                      "EMISSION_CARRY_B", "OPACITY", "DOUBLE_SIDED")

# Shader storage buffer bindings.
STORAGE_BINDING = {
    "VOXEL_SUMS": 0,        # the voxelizer's sums of the touched voxels, a record per slot (lib/voxel_sums.glsl)
    "FRONT_KEYS": 1,        # their front-layer keys and fragment counts, per slot and facing direction
    "TOUCHED_RECORDS": 2,   # per place on the touched list: the voxel's word of the record index before the update
    "TOUCHED": 14,          # voxels the current voxelization touched (count, then packed coordinates)
    "COVERED": 15,          # voxels holding surface
    "NEWLY_COVERED": 16,    # the voxels a voxelization covered that were empty
    "CELLS": 17,            # covered cells of the coarser levels, level after level
    "CELL_STAMPS": 18,
    "CLASS_LIST": 19,       # covered voxels sorted by interleave class, part (gather anchors, others), block, facing
    "CLASS_BUCKETS": 20,
    "READBACK": 21,
    "CONE_PIXELS": 22,      # pixels that trace cones of their own: dispatch size, count, pixels
    "SHARED_PIXELS": 23,    # pixels that take their cones' light from the anchors around them
    "EMITTER_TRIANGLES": 24,  # the emissive triangles (GLSL_STRUCTS["EmitterTriangle"])
    "EMITTER_PATCHES": 25,    # groups of them that share a visibility cone (GLSL_STRUCTS["EmitterPatch"])
    "GATHER_ANCHORS": 26,     # per record: whether its voxel traces the gather, or the anchors it takes it from
    "CELL_CLASS_BITS": 27,    # per level-1 cell: a bit per interleave class of the voxels in it
    "CELLS_BY_CLASS": 28,     # the covered level-1 cells sorted by class, the mixed ones last
    "STALE_VOXELS": 29,       # voxels whose gather-anchor records a voxelization may have changed
    "VOXEL_LIST": 30,         # the voxels injection, composition and the emitters' light run over (a VoxelSegment)
    "UNSHARED_PIXELS": 31,    # pixels between anchors that no anchor stood for: they trace their own cones
    "SEGMENTS": 32,           # rows of list segments the GPU counted (GLSL_STRUCTS["ListSegment"])
    "COUNTED": 33,            # a list whose count a segment row is sized from (voxel_grid/size_segment.comp)
    # Per-voxel data of the covered voxels, a record each (engine/voxels/records.py,
    # glsl/lib/voxel_records.glsl): each voxel's record, the free records, and the arrays of
    # RGBA16F values (two halves per uint) indexed by record.
    "VOXEL_RECORD": 34,       # per voxel: its record + 1, or 0 (no surface covers it)
    "RECORD_POOL": 35,        # the records no voxel holds
    "VOXEL_ALBEDO": 36,       # resolved surface: reflectance, a = 1
    "VOXEL_NORMAL": 37,       # xyz: mean normal (its length the coherence), w = 1
    "VOXEL_EMISSION": 38,     # rgb, a: the surface offset along the normal, in voxels
    "VOXEL_BASE": 39,         # emission + injected direct light
    "VOXEL_GATHERED": 40,     # the diffuse gather sum_j w_j L(p, w_j) of each voxel (the latest)
    "GATHERED_OUT": 41,       # a gather being written (or the sky's traced light, interpolated alike)
    "VOXEL_EMITTER_IRRADIANCE": 42,  # the emitters' shadowed irradiance (rgb), its visible fraction (a)
    "VOXEL_SKY_IRRADIANCE": 43,      # the sky's irradiance through the voxels (rgb), filtered
    "VOXEL_TRACED_SKY_IRRADIANCE": 44,  # the same as the anchors' cones traced it and the others interpolated it
    "VOXEL_REFLECTED": 46,    # the light each voxel's surface reflects (rgb), a = 1: level 0 of the face views
    "INSPECT_VALUES": 45,     # an array of values made a volume for inspection (voxel_grid/scatter_values.comp)
    # Drawing (engine/gpu/scene_buffers.py, engine/passes/cull.py, glsl/lib/draws.glsl): every draw's
    # record and every material's, the meshes' clusters, and a draw list's items, views, commands
    # and the instances the commands draw.
    "DRAWS": 47,              # a DrawRecord per draw
    "MATERIALS": 48,          # a MaterialRecord per material
    "CLUSTERS": 49,           # a Cluster per cluster of every mesh
    "DRAW_ITEMS": 50,         # what a draw list culls: a uvec4 (draw, cluster, command, 0) per draw and cluster
    "DRAW_VIEWS": 51,         # the views a draw list is drawn into (DrawView)
    "DRAW_COMMANDS": 52,      # indirect draw commands, 5 uints each (count, instances, first index, base vertex, base instance)
    "COMMAND_TABLE": 53,      # per command: index count, first index, base vertex, first instance slot per view
    "DRAW_INSTANCES": 54,     # per instance drawn: its draw (DRAW_INDEX_BITS) and view (from DRAW_VIEW_SHIFT)
    "HELD_DRAWS": 55,         # DrawRecords of draws as the voxels hold them (before they moved), for the voxelizer
    # Posing (engine/passes/pose.py, glsl/pose/pose_vertices.comp): the mesh pool's vertices
    # (a mesh's rest copy read, a posed draw's own copy written), a skinned mesh's influences
    # (PoseInfluence per vertex and set), a morphed mesh's displacements (position, normal,
    # tangent: three vec4 per vertex and target), the joint matrices and the target weights.
    "POSE_VERTICES": 56,
    "POSE_INFLUENCES": 57,
    "POSE_TARGETS": 58,
    "POSE_MATRICES": 59,
    "POSE_WEIGHTS": 60,
    "POSE_PREVIOUS": 62,      # per vertex of the pool, a posed draw's position at the frame before (vec4)
    "DRAW_MOTIONS": 61,       # per draw W_prev W^-1: a world point to where it was at the last frame (temporal/)
}

# A vertex of the mesh pool (engine/gpu/scene_buffers.py): interleaved float32 attributes,
# (vertex-shader input, floats); the pose pass reads and writes it as floats by these offsets.
VERTEX_ATTRIBUTES = (("in_position", 3), ("in_normal", 3), ("in_texcoord", 2), ("in_tangent", 4), ("in_color", 3),
                     ("in_texcoord1", 2))
VERTEX_FLOATS: GLSL_INT = sum(size for _, size in VERTEX_ATTRIBUTES)
VERTEX_NORMAL_AT: GLSL_INT = 3
# A material record's alpha cut-off (MaterialRecord.emission_cutoff.a): at least 0 for MASK
# (cut out below it), these for OPAQUE and for BLEND (blended over what lies behind; shadow maps
# and voxels dissolve it with probability 1 - alpha: lib/material.glsl).
ALPHA_OPAQUE: GLSL_FLOAT = -1.0
ALPHA_BLENDED: GLSL_FLOAT = -2.0
VERTEX_TANGENT_AT: GLSL_INT = 8

# Struct layouts shared with GLSL (vec4 and mat4 fields, so std140 and std430 lay them out
# alike): name -> ((GLSL type, field), ...). glsl_header() declares them, struct_dtype() gives
# the matching numpy record (a mat4 as its 16 floats, column by column).
GLSL_STRUCTS = {
    # A punctual light (glsl/lib/lights.glsl): world position (xyz) and LIGHT_TYPE (w); the
    # direction it shines (xyz) and its range (w, 0: no cut-off); W/sr or W/m^2 (rgb) and its
    # first shadow view (w, -1: none; a directional light's is its whole-scene view, its camera
    # cascades follow it); a spot's cos(inner angle), cos(outer angle) (xy), a directional
    # light's count of camera cascades (z).
    "Light": (("vec4", "position_type"), ("vec4", "direction_range"), ("vec4", "intensity_shadow"),
              ("vec4", "shape")),
    # One view of the shadow atlas: its view-projection; its tile's origin (xy) and size (zw) in
    # atlas uv; the world size of a texel per unit of clip w (x) and a texel's size in tile uv (y).
    "ShadowView": (("mat4", "view_projection"), ("vec4", "atlas_rect"), ("vec4", "texel")),
    # An emissive triangle in world space, front side by the right-hand rule: corners (xyz, w
    # unused) and its radiance (rgb, W/(m^2 sr); a unused).
    "EmitterTriangle": (("vec4", "a"), ("vec4", "b"), ("vec4", "c"), ("vec4", "radiance")),
    # Triangles of one emitter facing about one way: a sphere around them (centre xyz, radius
    # w), their mean plane through the centre (unit normal xyz, w: distance of the farthest
    # corner from it) and their range of the triangle list (first, count).
    "EmitterPatch": (("vec4", "sphere"), ("vec4", "plane"), ("uvec4", "triangles")),
    # A segment of a list: the group count of an indirect dispatch over it (x; y = z = 1) and
    # its first entry and count (xy of `range`), as the GPU counted them (engine/voxels/lists.py).
    "ListSegment": (("uvec4", "dispatch"), ("uvec4", "range")),
    # The camera a frame is seen from (frame.camera.FrameCamera, glsl/lib/camera.glsl): its
    # view-projection and inverse, its position (xyz; w: 1 where orthographic) and unit forward
    # direction (xyz).
    "FrameCamera": (("mat4", "view_projection"), ("mat4", "inverse_view_projection"), ("vec4", "position"),
                    ("vec4", "forward")),
    # A draw: its world matrix (normals go by its cofactors, glsl/lib/draws.glsl), its
    # material's index (info.x) and whether it is posed (info.y: 1, its own copy of its mesh).
    "DrawRecord": (("mat4", "world"), ("uvec4", "info")),
    # A material (engine.scene.model.Material, glsl/lib/material.glsl): albedo (rgb) and alpha factor
    # (a); emission (rgb) and alpha cut-off (a, negative: opaque); roughness, metalness,
    # dielectric F0 and normal scale; per map (MAP_*) its texture (array << 16 | layer; -1:
    # none), its texture coordinate set, and its coordinate transform as two rows (a, b, c, 0),
    # (d, e, f, 0): (u, v) -> (a u + b v + c, d u + e v + f); whether it is double-sided (sides.x).
    "MaterialRecord": (("vec4", "albedo_alpha"), ("vec4", "emission_cutoff"), ("vec4", "surface"), ("ivec4", "maps"),
                       ("ivec4", "uv_sets"), ("vec4", "uv_rows", 8), ("uvec4", "sides")),
    # A cluster of a mesh's triangles: its bounds in the mesh's frame (xyz of lo, hi) and its
    # indices: first index and count in the shared index buffer, the mesh's base vertex.
    "Cluster": (("vec4", "lo"), ("vec4", "hi"), ("uvec4", "indices")),
    # Four influences of a skinned vertex: joint indices into its skin and their weights.
    "PoseInfluence": (("uvec4", "joints"), ("vec4", "weights")),
    # A view a draw list is drawn into: its view-projection (frustum culling, and the shadow
    # views' drawing), a world box (box culling), a shadow view's tile in the atlas (NDC offset
    # xy, scale zw), a voxelization job's level (voxels_min.w) and voxels [min, max), and the
    # view's items (first, count) and tests (DRAW_TEST_* bits).
    "DrawView": (("mat4", "view_projection"), ("vec4", "box_min"), ("vec4", "box_max"), ("vec4", "tile"),
                 ("ivec4", "voxels_min"), ("ivec4", "voxels_max"), ("uvec4", "items")),
}
# An instance drawn from a draw list: its draw's index in the low DRAW_INDEX_BITS bits (a held
# draw's, DRAW_HELD set), its view's from DRAW_VIEW_SHIFT.
DRAW_INDEX_BITS = 24
DRAW_VIEW_SHIFT: GLSL_INT = 24
DRAW_HELD: GLSL_UINT = 1 << 31
NO_MATERIAL: GLSL_UINT = 0xFFFFFFFF  # a held draw's material in the voxelizer: it is marked as if not cut out
MAX_DRAW_VIEWS = 1 << (31 - DRAW_VIEW_SHIFT)  # 128
DRAW_INDEX_MASK: GLSL_UINT = (1 << DRAW_INDEX_BITS) - 1
DRAW_VIEW_MASK: GLSL_UINT = MAX_DRAW_VIEWS - 1
MAX_DRAWS = 1 << DRAW_INDEX_BITS
DRAW_TEST_FRUSTUM: GLSL_UINT = 1
DRAW_TEST_BOX: GLSL_UINT = 2

# Uniform block bindings (lights are read by every shaded pixel and voxel: uniform blocks are
# the fastest constant storage).
UNIFORM_BLOCK = {
    "LIGHTS": 0,
    "SHADOW_VIEWS": 1,
    "CAMERA": 2,  # the frame's camera (GLSL_STRUCTS["FrameCamera"]), written once a frame
}

MAX_LIGHTS: GLSL_INT = 16
MAX_SHADOW_VIEWS: GLSL_INT = 6 * MAX_LIGHTS  # a point light casts shadows through six cube faces
# Views of a directional light fitted to slices of the camera's frustum, after its whole-scene
# view (engine/passes/shadow.py, cascade_count): the pixels' light looks up the finest that
# holds them. With the whole-scene view, a point light's six views at most.
MAX_SHADOW_CASCADES: GLSL_INT = 5

LIGHT_TYPE = {"point": 0, "spot": 1, "directional": 2}

# Fixed point of the voxel sums: albedo (<= 1), unit normals and the surface offset (<= 1
# voxel) are stored as value * VOXEL_UNIT_SCALE; the signed sums have room for
# VOXEL_MAX_FRAGMENTS fragments per voxel (VOXEL_MAX_FRAGMENTS * VOXEL_UNIT_SCALE < 2^31).
VOXEL_UNIT_SCALE: GLSL_FLOAT = 4096.0
VOXEL_MAX_FRAGMENTS: GLSL_UINT = 2 ** 31 // int(VOXEL_UNIT_SCALE) - 1
# Emission radiance per fragment is clamped to the largest half float and stored as
# value * VOXEL_EMISSION_SCALE in 32 bits (65504 * 65536 < 2^32), summed in 64 bits.
VOXEL_EMISSION_SCALE: GLSL_FLOAT = 65536.0
VOXEL_MAX_EMISSION: GLSL_FLOAT = 65504.0

# GL formats of the voxel volumes and the render targets.
VOXEL_FORMAT = "f2"  # RGBA16F: HDR radiance without banding (field notes 9)
HDR_FORMAT = "f4"
GL_IMAGE_FORMAT = {"rgba16f": 0x881A, "rgba32f": 0x8814, "r32f": 0x822E, "r32ui": 0x8236}
# Voxel memory allowed before a grid is refused (bytes).
VOXEL_MEMORY_BUDGET = 4 * 2 ** 30
# One-sided views of the voxel radiance that cones read, one per axis direction (+x, -x, ...),
# stacked along z in one volume of n x n x 6n: a cone reads one view per axis with one sampler.
VOXEL_FACES: GLSL_INT = 6

GRID_SIZES = (16, 32, 64, 128, 256)
# A grid holds 1..MAX_VOXEL_LEVELS levels of N^3 (a clipmap's nested cubes; lib/voxel.glsl),
# stacked along z in voxel space: L N <= 4096 fits the packed z (VOXEL_PACK_BITS).
MAX_VOXEL_LEVELS: GLSL_INT = 10
# Lookups within this many voxels of a level's border (past the lookup's own reach) blend into
# the next coarser level, so a clipmap's level borders draw no seams (lib/voxel.glsl level_share).
LEVEL_BLEND_VOXELS: GLSL_FLOAT = 2.0

# Compute shader local sizes: passes over a list of voxels, and over a whole volume.
LIST_GROUP: GLSL_INT = 64
VOLUME_GROUP: GLSL_INT = 4
SCREEN_GROUP: GLSL_INT = 8  # a side of the square of pixels a screen pass's group takes
# Temporal anti-aliasing (engine/passes/temporal.py): the jitter cycles through this many points
# of the Halton sequence, and a pixel's history counts at most this many frames (its weight
# 1 / n: a still view's mean of the last TEMPORAL_FRAMES jittered samples).
TEMPORAL_FRAMES: GLSL_INT = 16
# A history pixel whose distance from the camera differs from the reprojected point's by more
# than this share of it saw another surface: dropped (disoccluded).
DISOCCLUSION_TOLERANCE: GLSL_FLOAT = 0.02
# The progressive bounce updates 1 interleave class of voxels in K per frame, K <=
# MAX_INTERLEAVE: a voxel's class is the position of its level-1 cell in the 2x2 block of
# cells along its surface, then the cell's layer (glsl/lib/gather_anchors.glsl, voxel_class).
MAX_INTERLEAVE: GLSL_INT = 8
# The covered-cell lists of the mip levels share one buffer, headed by a count per level.
CELL_LIST_LEVELS: GLSL_INT = 16
# Within a class the gather list runs block by block of CLASS_BLOCK^3 voxels, and within a
# block by facing (the mean normal's dominant axis and sign, or none: CLASS_FACINGS), so that
# the invocations running side by side trace neighbouring voxels along the same directions.
CLASS_BLOCK: GLSL_INT = 16
CLASS_FACINGS: GLSL_INT = 7
# A class's three parts: the voxels that trace the gather (anchors), those that interpolate
# it from them, and those beneath a finer level, which take it from the finer voxels tiling
# them (glsl/lib/gather_anchors.glsl).
CLASS_PARTS: GLSL_INT = 3
# The rows a bucket scan writes at most (gather/scan_buckets.comp: every voxel, then per class
# its voxels, its anchors, those that interpolate them, then per level those beneath a finer
# level), and its workgroup's size.
MAX_SEGMENT_ROWS: GLSL_INT = 1 + 3 * MAX_INTERLEAVE + MAX_INTERLEAVE * MAX_VOXEL_LEVELS
SCAN_GROUP: GLSL_INT = 256


def cone_cosine_centroid_tilt(tilt, half_angle, samples=400):
    """Polar angle of the cosine-weighted mean direction of a cone (axis `tilt` from the normal,
    half-angle `half_angle`), by midpoint quadrature over the cone's solid angle. A cone is
    marched as one ray of growing width, which averages radiance evenly over its solid angle;
    the diffuse integrand is cosine weighted, so the cone is marched along the direction that
    weighting pulls it to (first-order centroid rule). The weights are unchanged."""
    theta = (np.arange(samples) + 0.5) / samples * half_angle  # angle from the cone axis
    phi = (np.arange(samples) + 0.5) / samples * 2.0 * math.pi
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    # Ray directions with the cone axis tilted by `tilt` about y in the normal's frame (z = normal).
    x = np.sin(theta) * np.cos(phi)
    z = np.cos(theta)
    y = np.sin(theta) * np.sin(phi)
    dx = x * math.cos(tilt) + z * math.sin(tilt)
    dz = -x * math.sin(tilt) + z * math.cos(tilt)
    weight = np.sin(theta) * np.clip(dz, 0.0, None)  # solid angle element * cosine to the normal
    mean = np.array([(dx * weight).sum(), (y * weight).sum(), (dz * weight).sum()])
    return math.acos(mean[2] / np.linalg.norm(mean))


def lecture_cone_regions():
    """The regions of the lecture's 6 diffuse/AO cones: ([(tilt from the normal, azimuth)] of
    their axes, weights (6,), half_angle). One around the normal with weight 1/4, five around
    it, 72 degrees apart, covering 30..90 degrees from the normal (centred at 60 degrees), 3/20
    each; every region has half-angle pi/6, so they tile the hemisphere and the weights are
    their cosine-weighted shares (sin^2 30 = 1/4 for the central cap)."""
    axes = [(0.0, 0.0)] + [(math.radians(60.0), math.radians(72.0 * k)) for k in range(5)]
    weights = [0.25] + [3.0 / 20.0] * 5
    assert abs(sum(weights) - 1.0) < 1e-12, "diffuse cone weights must sum to 1"
    return axes, np.array(weights), math.pi / 6.0


def polar_direction(tilt, azimuth):
    """The unit vector `tilt` from z, turned by `azimuth` about it from x."""
    return np.array([math.sin(tilt) * math.cos(azimuth), math.sin(tilt) * math.sin(azimuth), math.cos(tilt)])


def diffuse_cones():
    """The lecture's 6 diffuse/AO cones in the local frame (z = normal): (directions (6,3),
    weights (6,), half_angle), one a region of lecture_cone_regions. The five tilted ones are
    marched along their regions' cosine centroid (52.8 degrees), see cone_cosine_centroid_tilt.
    """
    axes, weights, half_angle = lecture_cone_regions()
    directions = [polar_direction(cone_cosine_centroid_tilt(tilt, half_angle) if tilt else 0.0, azimuth) for tilt, azimuth in axes]
    return np.array(directions), weights, half_angle


def tiled_diffuse_cones():
    """The lecture's 6 cones, each traced as 7 narrower ones (the `tiled` diffuse cones).

    Returns (directions (42,3), weights (42,), half_angle) in the local frame (z = normal).
    Each of lecture_cone_regions is split into 7 cones of equal solid angle: one around the
    region's axis, six around it 60 degrees apart at the angular centroid of the ring they
    share (22.0 degrees out), each of half-angle acos(1 - (1 - cos(pi/6)) / 7) = 11.2 degrees. A
    cone's weight is its region's times its share of the region's cosine, cos(theta) over the
    seven's sum. A wide cone reads coarse cells that hold what its rays meet at different depths
    together (the lit face of an arcade and the dark vaults behind it); seven narrower ones each
    stop where their own rays do.
    """
    axes, region_weights, region_half_angle = lecture_cone_regions()
    half_angle = math.acos(1.0 - (1.0 - math.cos(region_half_angle)) / 7.0)
    theta = np.linspace(half_angle, region_half_angle, 1001)
    ring_angle = float((theta * np.sin(theta)).sum() / np.sin(theta).sum())  # centroid of the ring by solid angle
    directions, weights = [], []
    for (tilt, azimuth), region_weight in zip(axes, region_weights):
        axis = polar_direction(tilt, azimuth)
        side = np.cross([0.0, 1.0, 0.0] if tilt == 0.0 else [0.0, 0.0, 1.0], axis)
        side /= np.linalg.norm(side)
        up = np.cross(axis, side)
        cones = [axis] + [math.cos(ring_angle) * axis + math.sin(ring_angle) * (math.cos(a) * side + math.sin(a) * up)
                          for a in np.radians(60.0 * np.arange(6))]
        cosines = np.array([cone[2] for cone in cones])
        directions += cones
        weights += list(region_weight * cosines / cosines.sum())
    return np.array(directions), np.array(weights), half_angle


# The specular cones' lookups are at least 4 voxels wide (level 1): a narrow cone reading single
# voxels crosses an oblique plane's voxel staircase in 1, 2 or 3 voxels depending on where it
# meets a step, and draws the steps as stripes in glossy reflections.
SPECULAR_CONE_MIN_DIAMETER: GLSL_FLOAT = 4.0
# A specular cone counts the coverage of the cells it meets twice. Its lookups, a few voxels
# wide, cross an oblique plane's staircase over one voxel or two depending on where they meet
# a step: with the coverage counted once (one layer on average) the cone saw through where it
# crossed one, and drew the turned face a gold box reflects as stripes (contrast 0.020, the
# path tracer's 0.004); counted twice, the plane is opaque wherever it is crossed (0.002).
SPECULAR_CONE_OPACITY: GLSL_FLOAT = 2.0

# The sky's light at a voxel: SKY_CONE_COUNT cones over its hemisphere, uniform in solid angle
# (z = 1 - (j + u) / count, the golden angle apart in azimuth and turned by u'), each of the
# solid angle 2 pi / count, weighted by its cosine; u and u' are the voxel's own (a hash of its
# coordinates, glsl/sky_light/trace_sky_cones.comp), so neighbouring voxels sample the sky between each
# other's cones, and SKY_FILTER_RADIUS averages them (glsl/sky_light/filter_sky_light.comp).
SKY_CONE_COUNT: GLSL_INT = 32
SKY_CONE_HALF_ANGLE: GLSL_FLOAT = math.acos(1.0 - 1.0 / SKY_CONE_COUNT)
SKY_FILTER_RADIUS: GLSL_INT = 3
# While draws move, the sky's light is traced again at the voxels within this many times the
# largest moved draw's size of where they were and are, the others once the draws rest: an occluder of size s at distance d hides at
# most pi (s/2)^2 / d^2 of the sky's 2 pi, 1/72 at d = 3 s. The voxels relit, and the frame's
# cost, grow about as the cube of it (docs/PERFORMANCE.md, Sponza's object frame).
SKY_NEAR_REACH = 3.0
# The sky's cones read 2.75 mip levels below their footprint's (lookups over the inner 15 % of the
# cone's diameter, 2^-2.75) and step by those: a surface beside the cone (a wall along a cone that
# leaves through an opening) stays out of its lookups until the cone itself reaches it, where at
# the footprint's own level the lookups take it in long before. (Measured against path-traced
# skies through a ceiling opening, an open ceiling and Sponza's courtyard: docs/DESIGN.md, "Sky
# cones read finer".)
SKY_CONE_LEVEL_OFFSET: GLSL_FLOAT = 2.75
# The diffuse cones read 0.4 mip levels below their footprint's (lookups over 2^-0.4 of the
# cone's diameter) and still step by the footprint: at the footprint's own level the walls
# beside a cone cover it before it reaches what lies ahead, and light reflected from a bright
# patch a few metres away (the pool of a lamp near the floor) reached the rest of a room 14 %
# short at every grid size; 24 narrow cones read it in full (docs/DESIGN.md, "Diffuse cones
# read finer").
DIFFUSE_CONE_LEVEL_OFFSET: GLSL_FLOAT = 0.4


# Enumerations the host sets as uniforms and the shaders switch on, by name: GROUP_NAME in GLSL
# (TONEMAP_ACES), SHADER_ENUMS["TONEMAP"]["aces"] on the host.
SHADER_ENUMS = {
    "TONEMAP": {"none": 0, "reinhard": 1, "aces": 2},        # tonemap/tone_map.frag: the tone curve
    "OUTPUT": {"radiance": 0, "ao": 1},                       # cone_trace/shade_pixels.frag: what the image holds
    "VIEW": {"albedo": 0, "normal": 1, "depth": 2},           # gbuffer_view/show_gbuffer.frag: the G-buffer view
    "SHOW": {"radiance": 0, "normal": 1, "albedo": 2},        # voxel_view/march_voxels.frag: the voxel volume shown
    "VOXELIZE": {"mark": 0, "front": 1, "add": 2},            # voxelize/rasterize.frag: the stage of a voxelization
    "MAP": {"base_color": 0, "metal_rough": 1, "emissive": 2, "normal": 3},  # lib/material.glsl: a texture's
}                                                              # index in its per-map arrays (scene_gpu order)

# Voxel coordinates packed into one uint for the voxel lists: x | y << 10 | z << 20 (N <= 1024;
# z, which spans the levels, < 4096).
VOXEL_PACK_BITS: GLSL_INT = 10
NO_VOXEL: GLSL_UINT = 0xFFFFFFFF  # the packed word no voxel has: a list's entry that holds none (a free record's)
# While an update runs, a touched voxel's word of the record index holds TOUCHED_FLAG and its
# place on the touched list, or UNLISTED_PLACE where the list had no room left
# (lib/voxel_slots.glsl).
TOUCHED_FLAG: GLSL_UINT = 1 << 31
UNLISTED_PLACE: GLSL_UINT = TOUCHED_FLAG - 1
# A covered voxel's gather anchors (lib/gather_anchors.glsl): ANCHOR_SELF where it traces its own
# gather, ANCHOR_FINER where it takes it from the finer level's voxels beneath it, ANCHOR_STALE
# where a voxelization touched it; else a bit per anchor neighbour (0..25); and its facing
# (0..CLASS_FACINGS - 1, 3 bits) from bit ANCHOR_FACING_SHIFT.
ANCHOR_SELF: GLSL_UINT = 1 << 26
ANCHOR_STALE: GLSL_UINT = 1 << 27
ANCHOR_FINER: GLSL_UINT = 1 << 28
ANCHOR_NEIGHBOURS: GLSL_UINT = (1 << 26) - 1
ANCHOR_FACING_SHIFT: GLSL_INT = 29
MIN_ANCHOR_WEIGHT: GLSL_FLOAT = 0.2  # below this total weight of its anchors a voxel traces its own gather
# How much a voxel stands for a surface of unit normal n: max(0, n . n_v / |n_v|)^FACING_EXPONENT
# times the coherence |n_v| of its mean normal (lib/voxel.glsl: facing_weight).
FACING_EXPONENT: GLSL_FLOAT = 8.0
# Roughness below this is read as this (lib/brdf.glsl, engine/core/specular_lobe.py): the Blinn-Phong
# exponent 2 / r^4 - 2 stays finite.
MIN_ROUGHNESS: GLSL_FLOAT = 0.05
# What a pixel of the cone-trace list still needs (lib/cone_pixels.glsl): bit flags.
PIXEL_DIFFUSE_CONES: GLSL_UINT = 1
PIXEL_SPECULAR_CONE: GLSL_UINT = 2
PIXEL_AO_CONES: GLSL_UINT = 4


def struct_dtype(name):
    """The numpy record of a GLSL_STRUCTS layout (a field given a count is an array of it)."""
    kinds = {"vec4": ("<f4", 4), "uvec4": ("<u4", 4), "ivec4": ("<i4", 4), "mat4": ("<f4", 16)}
    return np.dtype([(member[1], kinds[member[0]][0], (*member[2:], kinds[member[0]][1]))
                     for member in GLSL_STRUCTS[name]])


def _glsl_define(name, value, kind):
    """A #define of an annotated constant: an int, a uint (hex, u) or a float (its shortest
    decimal form)."""
    if kind == GLSL_UINT:
        return f"#define {name} {int(value):#x}u"
    return f"#define {name} {float(value)!r}" if kind == GLSL_FLOAT else f"#define {name} {int(value)}"


@functools.lru_cache(maxsize=None)
def glsl_header():
    """GLSL source of the virtual include "engine_constants.glsl" (made once: every program
    includes it, and the cones' centroids and the specular table take a few tens of ms)."""
    lines = ["// Generated from engine/core/constants.py: edit there, not here."]
    for group, prefix in ((TEXTURE_UNIT, "TEX_"), (IMAGE_UNIT, "IMG_"), (STORAGE_BINDING, "SSBO_"), (UNIFORM_BLOCK, "UBO_")):
        lines += [f"#define {prefix}{name} {value}" for name, value in group.items()]
    lines += [f"#define SUM_{name} {index}" for index, name in enumerate(VOXEL_SUM_CHANNELS)]
    lines += [f"#define LIGHT_{name.upper()} {value}" for name, value in LIGHT_TYPE.items()]
    lines += [f"#define {group}_{name.upper()} {value}" for group, names in SHADER_ENUMS.items() for name, value in names.items()]
    lines.append(f"#define VOXEL_SUM_CHANNELS {len(VOXEL_SUM_CHANNELS)}")
    lines.append(f"#define PI {math.pi!r}")
    lines += [_glsl_define(name, globals()[name], kind) for name, kind in __annotations__.items()
              if kind in (GLSL_INT, GLSL_UINT, GLSL_FLOAT)]
    for name, members in GLSL_STRUCTS.items():
        lines.append(f"struct {name} {{ " + " ".join(f"{kind} {field}" + "".join(f"[{n}]" for n in count) + ";"
                                                    for kind, field, *count in members) + " };")
    for prefix, (directions, weights, half_angle) in (("DIFFUSE", diffuse_cones()), ("TILED", tiled_diffuse_cones())):
        lines.append(f"#define {prefix}_CONE_COUNT {len(weights)}")
        lines.append(f"#define {prefix}_CONE_HALF_ANGLE {half_angle:.9f}")
        dirs = ", ".join(f"vec3({d[0]:.9f}, {d[1]:.9f}, {d[2]:.9f})" for d in directions)
        lines.append(f"const vec3 {prefix}_CONE_DIRECTIONS[{len(weights)}] = vec3[]({dirs});")
        ws = ", ".join(f"{w:.9f}" for w in weights)
        lines.append(f"const float {prefix}_CONE_WEIGHTS[{len(weights)}] = float[]({ws});")
    from .specular_lobe import glsl_tables  # it reads MIN_ROUGHNESS from here
    lines += glsl_tables()
    return "\n".join(lines) + "\n"
