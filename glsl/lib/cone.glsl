// Cone marching through the mipmapped face views of the voxel radiance (premultiplied rgb,
// coverage in a). The face views hold the light surfaces reflect; emitted light reaches the
// diffuse cones' receivers as direct light (lib/emitters.glsl), and the specular cones add it
// from the emission volume. Level 0 is the voxels' records (their reflected light and mean
// normal, from which each face follows: voxel_face), the coarser levels a mipmapped volume.
#include "lib/voxel_surface.glsl"
#include "lib/hash.glsl"

// The light each voxel's surface reflects (rgb; faces/compose_face_views.comp), a = 1.
layout(std430, binding = SSBO_VOXEL_REFLECTED) readonly buffer VoxelReflected { uvec2 voxel_reflected[]; };
layout(binding = TEX_VOXEL_FACES) uniform sampler3D voxel_faces;      // the face views from level 1 up, stacked along z
// Emission (rgb) and coverage (a) from mip level 1 (cells of 2 voxels) up: what `emitted` cones
// add, which are at least SPECULAR_CONE_MIN_DIAMETER voxels wide (mip >= 1).
layout(binding = TEX_VOXEL_CONE_EMISSION) uniform sampler3D voxel_cone_emission;
uniform float cone_step;      // step length as a fraction of the cone diameter
uniform float cone_offset;    // start offset along the surface normal, in voxels
uniform float voxel_max_mip;  // log2(N): a level's 1^3 mip
uniform bool tiled_cones;     // the diffuse cones: the lecture's 6, or each as 7 narrower ones (trace_diffuse)

// Orthonormal basis whose third column is n.
mat3 tangent_frame(vec3 n) {
    vec3 helper = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 t = normalize(cross(helper, n));
    return mat3(t, cross(n, t), n);
}

// Share of a cone's rays travelling along +axis, for an axis component c of its direction and
// ray spread s = sin(half-angle): max(c, 0) for a thin cone, smoothed over [-s, s] so the
// rays of a wide cone that diverge towards a wall parallel to its axis still reach it.
float ray_share(float c, float spread) {
    if (c >= spread) return c;
    if (c <= -spread) return 0.0;
    return (c + spread) * (c + spread) / (4.0 * spread);
}

// The faces of a cell that a cone along w sees. Rays travelling along +k meet the faces looking
// along -k: per axis, the face looking against w_k (`face`) takes the share of rays going its
// way, and where |w_k| < spread the face looking along w_k (`back`) takes the rays that diverge
// the other way. A ray along w crosses the voxels of a plane with normal n over a path of
// max_j |n_j| / |n.w| voxels, where the face views hold |n_k| / max_j |n_j| (face_coverage):
// with weights |w_k| the plane adds up to sum_k |w_k n_k| / |n.w| = 1 layer at any angle, and a
// small surface to the share of the cone it projects onto. The back faces are kept minor axes
// first: the dominant axis (|w_k| >= 1/sqrt 3) has one only in cones wider than
// 35.3 degrees. Constant along a cone.
struct FaceWeights {
    ivec3 face;
    vec3 weight;
    ivec3 back;        // the two minor axes' back faces, then the dominant axis's
    vec3 back_weight;
    bvec3 along;       // per axis: the cone travels along +k (its face looks along -k: odd)
    vec3 back_weight_by_axis;  // back_weight per axis x, y, z
    vec3 front_cap;    // per axis: the share of the cone's rays travelling its way along it
};

// The share of a cone's rays (half-angle theta, uniform over its solid angle) whose direction
// has a positive component along an axis at elevation e = asin(c) from the plane normal to it:
// the part of a disc of radius theta beyond a chord e from its centre,
// 1/2 + (x sqrt(1 - x^2) + asin x) / pi with x = e / theta (within 0.5 % of the spherical cap's
// share at 30 degrees). Surfaces facing -k are met by those rays only: an infinite floor under a
// level cone takes half of it, not all.
float rays_along(float c, float half_angle) {
    float x = min(asin(c) / half_angle, 1.0);
    return 0.5 + (x * sqrt(1.0 - x * x) + asin(x)) / PI;
}

FaceWeights face_weights(vec3 w, float spread) {
    vec3 c = abs(w);
    int major = dominant_axis(w);
    ivec3 order = ivec3((major + 1) % 3, (major + 2) % 3, major);
    FaceWeights f;
    f.along = greaterThan(w, vec3(0.0));
    float half_angle = asin(spread);
    f.face = ivec3(0, 2, 4) + ivec3(f.along);
    for (int k = 0; k < 3; ++k) {
        f.weight[k] = ray_share(c[k], spread);
        f.back_weight_by_axis[k] = ray_share(-c[k], spread);
        f.front_cap[k] = rays_along(c[k], half_angle);
    }
    for (int k = 0; k < 3; ++k) {
        int axis = order[k];
        f.back[k] = 2 * axis + int(w[axis] <= 0.0);
        f.back_weight[k] = f.back_weight_by_axis[axis];
    }
    return f;
}

// A voxel's face view: its reflected light premultiplied by the coverage of that face
// (face_coverage), coverage in a.
vec4 voxel_face(vec3 reflected, float coverage) {
    return coverage * vec4(reflected, 1.0);
}

// One face view around uvw (in level `level`'s cube) at a mip level of 1 or more (a fractional
// one blends the two levels around it), filtered within the view and level: the depth
// coordinate is clamped to the coarser mip level's own texels (stacked_uvw).
vec4 face_lod(int face, vec3 uvw, int level, float mip) {
    float side = float(voxel_grid >> int(ceil(mip)));
    return textureLod(voxel_faces, stacked_uvw(uvw, level, face, VOXEL_FACES, side), mip - 1.0);  // it holds levels 1 and up
}

// How much of a voxel with mean normal n a cone sees through its face weights, per axis: front_share
// of the faces it looks into (front), and the back faces where `backs` (as sample_faces weighs the
// views; a back face takes rays only where its weight is nonzero, the dominant axis's in wide cones).
struct SeenCoverage {
    vec3 front;
    vec3 back;
};

SeenCoverage seen_coverage(vec3 n, FaceWeights f, float front_share, bool backs) {
    FaceCoverage c = face_coverages(n);
    return SeenCoverage(front_share * f.weight * mix(c.plus, c.minus, f.along),
                        backs ? f.back_weight_by_axis * mix(c.minus, c.plus, f.along) : vec3(0.0));
}

// Add a voxel side with reflected light `reflected` and mean normal n, at `weight` (its share of
// the lookup times its opacity), to a lookup's premultiplied sum and its coverage per axis.
void add_seen_side(inout vec4 sum, inout SeenCoverage seen, vec3 reflected, vec3 n, float weight, FaceWeights f,
                   float front_share, bool backs) {
    SeenCoverage side = seen_coverage(n, f, front_share, backs);
    sum += voxel_face(reflected, weight * (dot(side.front, vec3(1.0)) + dot(side.back, vec3(1.0))));
    seen.front += weight * side.front;
    seen.back += weight * side.back;
}

// The face views at mip level 0 around uvw (in level `level`'s cube), read as a trilinear lookup
// would read them from a volume: the 8 voxels around uvw (clamped to the level, as the lookups
// clamp), each weighted by its share of the lookup and seen through the face weights
// (seen_coverage), their coverage per axis added to `seen`.
vec4 faces_at_level_zero(vec3 uvw, int level, FaceWeights f, float front_share, bool backs, inout SeenCoverage seen) {
    TrilinearVoxels lookup = trilinear_voxels(uvw);
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 8; ++k) {
        uint record = level_record(clamp(lookup.first + corner_offset(k), ivec3(0), ivec3(voxel_grid - 1)), level);
        if (record == NO_RECORD) continue;
        // Each side seen through the faces it faces (the second where the voxel has two).
        vec4 side_0_normal = unpack_value(voxel_normal[side_value(record, 0)]);
        float weight = trilinear_weight(lookup, k);
        for (int side = 0; side < sides_of(side_0_normal); ++side) {
            vec4 normal = side_normal(record, side, side_0_normal);  // w: its opacity
            add_seen_side(sum, seen, unpack_value(voxel_reflected[side_value(record, side)]).rgb, normal.xyz,
                          weight * abs(normal.w), f, front_share, backs);
        }
    }
    return sum;
}

// Premultiplied radiance (rgb) and coverage (a) of the cell around uvw at a mip level, as seen
// by a cone with the given face weights. The faces the cone looks into read `mip` (two levels
// blended where it is fractional), the back faces, which take the small shares of the rays that
// diverge sideways, the nearest level: a blended lookup reads twice the texels, and the back
// faces' jumps between levels do not show (front faces read at the nearest level too made
// coarse grids read bright against the path tracer). The dominant axis's back face takes rays
// only in cones wider than 35.3 degrees (face_weights): `wide` ones. `seen`: the coverage read
// through each axis's front and back faces (their sum is a).
vec4 sample_faces(vec3 uvw, int level, float mip, FaceWeights f, bool wide, out SeenCoverage seen) {
    float nearest = round(mip);
    float level_zero_share = max(1.0 - mip, 0.0);  // of the front faces' lookups, blended
    vec4 sum = vec4(0.0);
    seen = SeenCoverage(vec3(0.0), vec3(0.0));
    if (mip > 0.0) {
        float coarse = max(mip, 1.0);
        float share = 1.0 - level_zero_share;
        vec4 x = face_lod(f.face.x, uvw, level, coarse), y = face_lod(f.face.y, uvw, level, coarse),
             z = face_lod(f.face.z, uvw, level, coarse);
        sum += share * (f.weight.x * x + f.weight.y * y + f.weight.z * z);
        seen.front += share * f.weight * vec3(x.a, y.a, z.a);
    }
    // A back face no ray diverges to (|w_k| >= spread) is not read: most cones have one or none.
    if (nearest > 0.0) {
        for (int k = 0; k < 3; ++k) {
            if (f.back_weight[k] <= 0.0 || (k == 2 && !wide)) continue;
            vec4 back = f.back_weight[k] * face_lod(f.back[k], uvw, level, nearest);
            sum += back;
            seen.back[f.back[k] >> 1] += back.a;
        }
    }
    if (level_zero_share > 0.0 || nearest == 0.0) sum += faces_at_level_zero(uvw, level, f, level_zero_share, nearest == 0.0, seen);
    return sum;
}

// How a kind of cone reads the voxels (trace_cone), one description per kind below.
struct ConeReading {
    // Wider than 35.3 degrees, so the back face of a cell's dominant axis takes rays
    // (face_weights; narrower cones skip it: a compile-time branch for the kinds always narrow).
    bool wide;
    // Read that many levels below the footprint's: narrower lookups than the cone (the diffuse
    // and sky cones), which sample the surfaces it sweeps more finely.
    float level_offset;
    // Step by the lookups' diameter (the narrowed ones: the sky's cones, and the others, which
    // are not narrowed), else by the cone's (the diffuse cones: less than a level finer, their
    // steps span 1.3 of their cells and the opacity counts the step's length).
    bool step_by_lookup;
    // The narrowest lookups, in voxels of the level holding the step (1, or
    // SPECULAR_CONE_MIN_DIAMETER): a narrow cone passing into a coarser level steps as one that
    // started there.
    float min_diameter;
    // How many times a cell's coverage counts (1, or SPECULAR_CONE_OPACITY).
    float opacity_scale;
    // Read the two mip levels around the footprint blended (the diffuse and sky cones: at the
    // nearest level the reading jumps where the distance to a surface crosses from one level to
    // the next, which draws bands on the receivers), else the nearest one (the specular and
    // emitter cones: narrow and long, most of their steps fall between levels 0 and 1, where
    // blending doubles the texel reads for images that hardly differ).
    bool blend_mips;
    // Near a level's border read one of the two levels, chosen by a hash of the step's point with
    // odds of their shares (the same blend on average, and no second lookup), else both, weighed
    // by their shares. The cones from voxels dither: their light reaches the image through
    // trilinear lookups and interpolation that average it over many voxels and steps. The
    // screen's cones blend: a pixel's own choice would show as grain.
    bool dither_levels;
    // Add the emission of the surfaces met (the specular cones) from the emission volume: its
    // mean over the covered voxels of the cell, e.rgb / e.a, seen from every side.
    bool emitted;
    // The first lookup's distance along the cone from its start point, in the start level's
    // voxels: 1 (past the voxel the start point lies in), 0 for the tiled diffuse cones
    // (trace_diffuse).
    float start_distance;
};

// The kinds of cone. An emitter's cone is as wide as its patch: EMITTER_READING with `wide` set.
//                                                    wide   level_offset               step_by_lookup min_diameter                opacity_scale          blend_mips dither_levels emitted start_distance
const ConeReading SCREEN_DIFFUSE_READING = ConeReading(false, DIFFUSE_CONE_LEVEL_OFFSET, false,         1.0,                        1.0,                   true,      false,        false,  1.0);
const ConeReading VOXEL_DIFFUSE_READING  = ConeReading(false, DIFFUSE_CONE_LEVEL_OFFSET, false,         1.0,                        1.0,                   true,      true,         false,  1.0);
const ConeReading SPECULAR_READING       = ConeReading(true,  0.0,                       true,          SPECULAR_CONE_MIN_DIAMETER, SPECULAR_CONE_OPACITY, false,     false,        true,   1.0);
const ConeReading SKY_READING            = ConeReading(false, SKY_CONE_LEVEL_OFFSET,     true,          1.0,                        1.0,                   true,      true,         false,  1.0);
const ConeReading EMITTER_READING        = ConeReading(false, 0.0,                       true,          1.0,                        1.0,                   false,     true,         false,  1.0);

// A cone's lookup at p in level `level` for lookups at mip `mip` (in the finest level's voxels;
// level k reads its own mip - k, which is 1..2 where the level matches the footprint), a step of
// `step_length` on (trace_cone): the radiance it meets (rgb, emission added where the reading
// says) and the covered fraction of the step's cross-section (a), split per axis in `seen`.
vec4 level_lookup(vec3 p, int level, float mip, FaceWeights weights, ConeReading reading, float step_length,
                  out SeenCoverage seen) {
    float local_mip = clamp(mip - float(level), 0.0, voxel_max_mip);
    if (!reading.blend_mips) local_mip = round(local_mip);
    vec3 uvw = level_uvw(p, level);
    vec4 s = sample_faces(uvw, level, local_mip, weights, reading.wide, seen);
    if (s.a <= 0.0) return vec4(0.0);
    // c = min(1, a 2^mip) over cells 2^mip of the level's voxels (trace_cone)
    float cell = exp2(local_mip) * level_voxel_size[level];
    float coverage = reading.opacity_scale * min(1.0, s.a * exp2(local_mip)) * step_length / cell;
    seen.front *= coverage / s.a;  // each axis's faces' part of it
    seen.back *= coverage / s.a;
    vec3 radiance = s.rgb / s.a;
    if (reading.emitted && voxel_emitters) {
        vec3 e_uvw = stacked_uvw(uvw, level, 0, 1, float(voxel_grid >> int(ceil(local_mip))));
        vec4 e = textureLod(voxel_cone_emission, e_uvw, local_mip - 1.0);  // it holds mips 1 and up
        if (e.a > 0.0) radiance += e.rgb / e.a;
    }
    return vec4(radiance, coverage);
}

// Radiance (rgb) and opacity (a) gathered along a cone from surface point p with normal n
// whose voxels are `start_level`'s, starting cone_offset of its voxels out along the normal and
// the reading's start_distance along the cone, one sample per step, read as `reading`
// describes. Each lookup reads the level whose voxels are half its cells (the levels take the
// place of the single grid's mips past the finest; at least start_level, the finest holding
// the lookup: holding_level), blended into the next coarser one near the level's border
// (level_share).
// With voxel the side of the voxels of the finest level from the start level up that holds the
// step's point, v0 the finest level's, and the reading's level_offset, min_diameter and
// opacity_scale k:
//   D = max(min_diameter voxel, 2 tan(a/2) t)    the cone's diameter at distance t, at least
//                                                the narrowest lookup's
//   d = max(min_diameter voxel, D 2^-level_offset)   the lookups' diameter (narrowed)
//   mip = log2(d / v0) - 1                       a trilinear lookup averages over a tent two
//                                                cells wide, so cells of d/2 span d
//   c = min(1, a 2^mip)                          a mip cell 2^mip voxels wide with mean coverage
//                                                a holds a 2^mip voxel layers of surface across
//                                                the cone: a plane stays opaque at every level
//   alpha += min(k c step / (2^mip v0), 1 - alpha)  the covered fraction of a step through
//                                                cells 2^mip voxels wide, front to back, which
//                                                makes the result independent of the step,
//                                                split among the faces read; the faces facing
//                                                against an axis's travel cover at most the
//                                                share of rays travelling that way (rays_along),
//                                                those facing along it the rest
//   t += step = cone_step * (step_by_lookup ? d : D)
vec4 trace_cone(vec3 p, vec3 n, int start_level, vec3 direction, float tan_half_angle, float max_distance,
                ConeReading reading) {
    float unit = level_voxel_size[start_level];
    vec3 start = p + n * (cone_offset * unit);
    vec4 gathered = vec4(0.0);
    float spread = tan_half_angle / sqrt(1.0 + tan_half_angle * tan_half_angle);  // sin(half-angle)
    FaceWeights weights = face_weights(direction, spread);
    float t = reading.start_distance * unit;
    float narrowing = exp2(-reading.level_offset);
    float top_mip = voxel_max_mip + float(voxel_levels - 1);  // the coarsest level's 1^3
    // Near a level's border a step that does not dither reads the level (its share) and then, in
    // the next pass of the loop, the next coarser level (the rest): one lookup a pass keeps the
    // loop small.
    bool coarser_due = false;
    vec4 finer = vec4(0.0);  // the finer level's share of the step, premultiplied, while coarser_due
    SeenCoverage finer_seen = SeenCoverage(vec3(0.0), vec3(0.0));
    // The coverage taken so far from the surfaces facing against each axis's travel (front) and
    // along it (back), each at most the share of the rays that can meet them (front_cap).
    vec3 covered_front = vec3(0.0), covered_back = vec3(0.0);
    vec3 back_cap = 1.0 - weights.front_cap;
    float cone_diameter, diameter, mip, step_length, share;
    vec3 q;
    int level;
    while (gathered.a < 1.0 && t < max_distance) {
        if (!coarser_due) {
            q = start + direction * t;
            // The narrowest lookup: min_diameter voxels of the finest level that holds q (from
            // the start level up: no finer level is read).
            int point_level = holding_level(q, start_level, 0.0, 0.0);
            float narrowest = reading.min_diameter * level_voxel_size[point_level];
            cone_diameter = max(narrowest, 2.0 * tan_half_angle * t);
            diameter = max(narrowest, narrowing * cone_diameter);
            mip = min(max(log2(diameter / voxel_size) - 1.0, 0.0), top_mip);
            // A lookup reaches half a cell (d/4) past its point: cells whose centres lie within a
            // cell of it, half a cell wide each side.
            float reach = 0.25 * diameter;
            // No level finer than point_level holds q, let alone the lookup's reach around it.
            level = holding_level(q, clamp(max(int(mip) - 1, point_level), start_level, voxel_levels - 1), reach, 0.0);
            // Stop half a cell past the coarsest level: the lookups clamp to the outer cells, which
            // hold the surfaces at its edge once; further out they would repeat them.
            if (level_depth(q, level) < -level_reach(level, reach, 0.0)) break;
            step_length = cone_step * (reading.step_by_lookup ? diameter : cone_diameter);
            share = level_share(q, level, level_reach(level, reach, 0.0));
            if (reading.dither_levels && share < 1.0) {  // one of the two levels, chosen with odds share : 1 - share
                if (point_hash(q) >= share) ++level;
                share = 1.0;
            }
        }
        SeenCoverage seen;
        vec4 lookup = level_lookup(q, coarser_due ? level + 1 : level, mip, weights, reading, step_length, seen);
        float level_part = coarser_due ? 1.0 - share : share;
        vec4 s = finer + level_part * vec4(lookup.rgb * lookup.a, lookup.a);
        seen.front = finer_seen.front + level_part * seen.front;
        seen.back = finer_seen.back + level_part * seen.back;
        if (!coarser_due && share < 1.0) {
            finer = s;
            finer_seen = seen;
            coarser_due = true;
            continue;
        }
        coarser_due = false;
        finer = vec4(0.0);
        finer_seen = SeenCoverage(vec3(0.0), vec3(0.0));
        if (s.a > 0.0) {
            // Covered fraction of the cross-section added by this step, front to back, each
            // facing's part within the rays left that can meet it.
            vec3 front = clamp(weights.front_cap - covered_front, vec3(0.0), seen.front);
            vec3 back = clamp(back_cap - covered_back, vec3(0.0), seen.back);
            covered_front += front;
            covered_back += back;
            float alpha = min(dot(front, vec3(1.0)) + dot(back, vec3(1.0)), 1.0 - gathered.a);
            gathered.rgb += alpha * (s.rgb / s.a);
            gathered.a += alpha;
        }
        t += step_length;
    }
    return gathered;
}

// Diffuse gather with the lecture's 6 cones from p in start_level, or each of them traced as 7
// narrower ones where `tiled_cones` (engine/core/constants.py: tiled_diffuse_cones), read as
// `reading` describes (SCREEN_DIFFUSE_READING or VOXEL_DIFFUSE_READING: 0.4 levels finer than
// their footprints): returns sum_j w_j Lv(p, w_j) (rgb) and the cosine-weighted occlusion
// sum_j w_j a_j (a).
vec4 trace_diffuse(vec3 p, vec3 n, int start_level, float max_distance, ConeReading reading) {
    mat3 frame = tangent_frame(n);
    // The tiled cones read from their start point on: a lookup a voxel wide one voxel along a
    // steep one leaves the voxel before it unread, where it crosses the floor at a wall's foot
    // (the six's lookups, wider, reach back over it).
    ConeReading cone_reading = reading;
    if (tiled_cones) cone_reading.start_distance = 0.0;
    int count = tiled_cones ? TILED_CONE_COUNT : DIFFUSE_CONE_COUNT;
    float tan_half = tan(tiled_cones ? TILED_CONE_HALF_ANGLE : DIFFUSE_CONE_HALF_ANGLE);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < count; ++j) {
        vec3 direction;
        float weight;
        if (tiled_cones) {
            direction = TILED_CONE_DIRECTIONS[j];
            weight = TILED_CONE_WEIGHTS[j];
        } else {
            direction = DIFFUSE_CONE_DIRECTIONS[j];
            weight = DIFFUSE_CONE_WEIGHTS[j];
        }
        sum += weight * trace_cone(p, n, start_level, frame * direction, tan_half, max_distance, cone_reading);
    }
    return sum;
}
