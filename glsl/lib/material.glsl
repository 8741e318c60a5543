// The material of the surface being drawn (engine.scene.Material): its factors times its
// textures at the surface's texture coordinates, the base colour times the mesh's vertex
// colour. A material without a texture has a white one bound (a flat normal for the normal
// map), so every factor is sampled the same way. Where VERTEX_EXTRAS is defined (draws whose
// mesh has vertex colours or a second texture coordinate set, or whose material transforms its
// texture coordinates), each texture reads set 0 or 1 through its own 2D affine transform
// (KHR_texture_transform); elsewhere every texture reads set 0 as it is, sparing the other
// draws' fragments the transforms.
#include "engine_constants.glsl"

layout(binding = TEX_BASE_COLOR_MAP) uniform sampler2D base_color_map;    // sRGB, decoded by the sampler
layout(binding = TEX_METAL_ROUGH_MAP) uniform sampler2D metal_rough_map;  // G roughness, B metalness
layout(binding = TEX_EMISSIVE_MAP) uniform sampler2D emissive_map;        // sRGB
layout(binding = TEX_NORMAL_MAP) uniform sampler2D normal_map;            // tangent space, 0.5 n + 0.5
uniform vec3 albedo;
uniform float alpha;
uniform float roughness;
uniform float metalness;
uniform float dielectric_f0;
uniform vec3 emission;
uniform float normal_scale;
uniform float alpha_cutoff;  // cut out where alpha < alpha_cutoff; negative: opaque
uniform mat3 uv_transforms[4];  // per map (MAP_*, engine/constants.py): (u, v, 1) -> its coordinates
uniform ivec4 uv_sets;          // per map: texture coordinate set 0 or 1

// The texture coordinates map `map` reads, from the surface's two sets.
vec2 map_uv(int map, vec2 uv0, vec2 uv1) {
#ifdef VERTEX_EXTRAS
    return (uv_transforms[map] * vec3(uv_sets[map] == 1 ? uv1 : uv0, 1.0)).xy;
#else
    return uv0;
#endif
}

struct MaterialSample {
    vec3 albedo;
    float alpha;
    float roughness;
    float metalness;
    vec3 emission;
};

// The material at the surface's texture coordinates uv0, uv1 with vertex colour `color`,
// filtered over the fragment's footprint (a pixel of the image, a voxel, a shadow texel):
// trilinear, at the level of detail of the footprint's longest side.
MaterialSample sample_material(vec2 uv0, vec2 uv1, vec3 color) {
    MaterialSample m;
    vec4 base = texture(base_color_map, map_uv(MAP_BASE_COLOR, uv0, uv1));
    vec4 metal_rough = texture(metal_rough_map, map_uv(MAP_METAL_ROUGH, uv0, uv1));
    m.albedo = albedo * base.rgb * color;
    m.alpha = alpha * base.a;
    m.roughness = roughness * metal_rough.g;
    m.metalness = metalness * metal_rough.b;
    m.emission = emission * texture(emissive_map, map_uv(MAP_EMISSIVE, uv0, uv1)).rgb;
    return m;
}

// True where an alpha-tested material is cut out.
bool cut_out(float material_alpha) {
    return alpha_cutoff >= 0.0 && material_alpha < alpha_cutoff;
}

// The shading normal of a material with a normal map: its normal in the tangent frame
// (tangent.xyz, bitangent tangent.w cross(n, tangent)), its x and y scaled by normal_scale; the
// surface normal n where the mesh has no tangents.
vec3 shading_normal(vec3 n, vec4 tangent, vec2 uv0, vec2 uv1) {
    if (dot(tangent.xyz, tangent.xyz) == 0.0) return n;
    vec3 t = normalize(tangent.xyz - n * dot(n, tangent.xyz));
    vec3 b = tangent.w * cross(n, t);
    vec3 m = texture(normal_map, map_uv(MAP_NORMAL, uv0, uv1)).xyz * 2.0 - 1.0;
    return normalize(t * (m.x * normal_scale) + b * (m.y * normal_scale) + n * m.z);
}
