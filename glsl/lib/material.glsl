// The material of the surface being drawn (engine.scene.model.Material): its record in the materials'
// buffer (engine/gpu/scene_buffers.py, GLSL_STRUCTS["MaterialRecord"]), its factors times its textures at
// the surface's texture coordinates, the base colour times the mesh's vertex colour. A texture
// is a layer of one of the texture arrays every draw binds; a map without a texture reads white
// (a flat normal for the normal map is never read: such draws have no NORMAL_MAP). Draws whose
// mesh has vertex colours or a second texture coordinate set, or whose material transforms its
// texture coordinates (the programs with VERTEX_EXTRAS), read each texture at set 0 or 1
// through its own 2D affine transform (KHR_texture_transform: material_coordinates); the others
// read every texture at set 0 as it is (same_coordinates), sparing their vertices and
// fragments the transforms. A draw list's commands each draw one material, so the texture
// array a fragment picks is the same across its draw.
#include "engine_constants.glsl"
#include "lib/hash.glsl"

layout(binding = TEX_MATERIAL_TEXTURES) uniform sampler2DArray material_textures[MATERIAL_TEXTURE_ARRAYS];
layout(std430, binding = SSBO_MATERIALS) readonly buffer Materials { MaterialRecord materials[]; };

// The texture coordinates of each map (MAP_*): maps 0 and 1 in xy and zw of `maps01`, 2 and 3 of
// `maps23`.
struct MapCoordinates {
    vec4 maps01;
    vec4 maps23;
};

// Every map reading the surface's one set of texture coordinates as it is.
MapCoordinates same_coordinates(vec2 uv) {
    return MapCoordinates(uv.xyxy, uv.xyxy);
}

// Each map's texture coordinates from the surface's two sets, through its transform: computed
// where the vertices are (the transforms are affine) and interpolated, so that what a fragment
// samples at never depends on a buffer read of its own (whose helper invocations, which give the
// texture lookups their derivatives, read nothing on llvmpipe).
MapCoordinates material_coordinates(uint material, vec2 uv0, vec2 uv1) {
    MaterialRecord record = materials[material];
    vec2 uv[4];
    for (int map = 0; map < 4; ++map) {
        vec3 set = vec3(record.uv_sets[map] == 1 ? uv1 : uv0, 1.0);
        uv[map] = vec2(dot(record.uv_rows[2 * map].xyz, set), dot(record.uv_rows[2 * map + 1].xyz, set));
    }
    return MapCoordinates(vec4(uv[0], uv[1]), vec4(uv[2], uv[3]));
}

vec2 map_uv(MapCoordinates coordinates, int map) {
    vec4 pair = map < 2 ? coordinates.maps01 : coordinates.maps23;
    return (map & 1) == 0 ? pair.xy : pair.zw;
}

// Map `map` of the material at its texture coordinates; `none` without a texture.
vec4 sample_map(MaterialRecord record, int map, MapCoordinates coordinates, vec4 none) {
    int slot = record.maps[map];
    if (slot < 0) return none;
    return texture(material_textures[slot >> 16], vec3(map_uv(coordinates, map), float(slot & 0xffff)));
}

struct MaterialSample {
    vec3 albedo;
    float alpha;
    float roughness;
    float metalness;
    vec3 emission;
    float dielectric_f0;
    float alpha_cutoff;  // cut out where alpha < alpha_cutoff; ALPHA_OPAQUE, ALPHA_BLENDED
};

// The material at the surface's map coordinates with vertex colour `color`, filtered over the
// fragment's footprint (a pixel of the image, a voxel, a shadow texel): trilinear, at the level
// of detail of the footprint's longest side.
MaterialSample sample_material(uint material, MapCoordinates coordinates, vec3 color) {
    MaterialRecord record = materials[material];
    MaterialSample m;
    vec4 base = sample_map(record, MAP_BASE_COLOR, coordinates, vec4(1.0));
    vec4 metal_rough = sample_map(record, MAP_METAL_ROUGH, coordinates, vec4(1.0));
    m.albedo = record.albedo_alpha.rgb * base.rgb * color;
    m.alpha = record.albedo_alpha.a * base.a;
    m.roughness = record.surface.x * metal_rough.g;
    m.metalness = record.surface.y * metal_rough.b;
    m.emission = record.emission_cutoff.rgb * sample_map(record, MAP_EMISSIVE, coordinates, vec4(1.0)).rgb;
    m.dielectric_f0 = record.surface.z;
    m.alpha_cutoff = record.emission_cutoff.a;
    return m;
}

// Whether an alpha-tested (MASK) material cuts the surface out.
bool cut_out(MaterialSample m) {
    return m.alpha_cutoff >= 0.0 && m.alpha < m.alpha_cutoff;
}

// Whether a blended material is dissolved at a fragment of a shadow map or a voxel: with
// probability 1 - alpha, by a hash of `place` (its texel, its voxel), so that a surface of alpha
// a stops a of the light that crosses it on average (stochastic transparency).
bool dissolved(MaterialSample m, vec3 place) {
    return m.alpha_cutoff == ALPHA_BLENDED && m.alpha <= point_hash(place);
}

// Whether the material's alpha cuts anything out or dissolves it (MASK, BLEND).
bool alpha_tested(uint material) {
    return materials[material].emission_cutoff.a != ALPHA_OPAQUE;
}

// The shading normal of a material with a normal map: its normal in the tangent frame
// (tangent.xyz, bitangent tangent.w cross(n, tangent)), its x and y scaled by its normal scale;
// the surface normal n where the mesh has no tangents.
vec3 shading_normal(uint material, vec3 n, vec4 tangent, MapCoordinates coordinates) {
    if (dot(tangent.xyz, tangent.xyz) == 0.0) return n;
    MaterialRecord record = materials[material];
    vec3 t = normalize(tangent.xyz - n * dot(n, tangent.xyz));
    vec3 b = tangent.w * cross(n, t);
    vec3 m = sample_map(record, MAP_NORMAL, coordinates, vec4(0.5, 0.5, 1.0, 1.0)).xyz * 2.0 - 1.0;
    float scale = record.surface.w;
    return normalize(t * (m.x * scale) + b * (m.y * scale) + n * m.z);
}
