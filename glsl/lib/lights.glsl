// Punctual lights and their shadow maps, shared by the lighting pass and voxel injection.
#include "engine_constants.glsl"

// The structs Light and ShadowView are engine/core/constants.py's GLSL_STRUCTS.
layout(std140, binding = UBO_LIGHTS) uniform LightBuffer { Light lights[MAX_LIGHTS]; };
layout(std140, binding = UBO_SHADOW_VIEWS) uniform ShadowBuffer { ShadowView shadow_views[MAX_SHADOW_VIEWS]; };
layout(binding = TEX_SHADOW_ATLAS) uniform sampler2DShadow shadow_atlas;
uniform int light_count;
uniform float shadow_normal_offset; // in shadow-map texels

// Cube face of a direction, in the order +x, -x, +y, -y, +z, -z.
int cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0 : 1;
    if (a.y >= a.z) return d.y >= 0.0 ? 2 : 3;
    return d.z >= 0.0 ? 4 : 5;
}

// The view of a light's shadows p is looked up in: where `camera_cascades`, a directional
// light's finest camera cascade that holds p with room for the lookup's offset and 2x2 filter;
// a point light's cube face of p; else the light's first view (a directional light's whole scene).
int shadow_view_index(Light light, vec3 p, bool camera_cascades) {
    int first = int(light.intensity_shadow.w);
    int type = int(light.position_type.w);
    if (type == LIGHT_POINT) return first + cube_face(p - light.position_type.xyz);
    if (type == LIGHT_DIRECTIONAL && camera_cascades) {
        for (int k = 1; k <= int(light.shape.z); ++k) {
            ShadowView view = shadow_views[first + k];
            vec2 ndc = (view.view_projection * vec4(p, 1.0)).xy; // orthographic: w = 1
            if (all(lessThan(abs(ndc), vec2(1.0 - 2.0 * (shadow_normal_offset + 2.0) * view.texel.y)))) return first + k;
        }
    }
    return first;
}

// Fraction of the light that reaches p (1 lit, 0 shadowed), 2x2 hardware PCF. `lift`: how far
// (world units) the surface p stands for may reach out of p along n, added to the lookup's
// offset; `camera_cascades`: p is a point the camera sees (shadow_view_index).
float shadow_visibility(Light light, vec3 p, vec3 n, vec3 to_light, float lift, bool camera_cascades) {
    if (light.intensity_shadow.w < 0.0) return 1.0;
    ShadowView view = shadow_views[shadow_view_index(light, p, camera_cascades)];
    // Normal offset: move the lookup off the surface by a few texels times sin(theta), the angle
    // between the normal and the light (no acne where the light grazes, where a texel spans the
    // most depth; no lost contact shadows where it faces the surface).
    float texel_world = view.texel.x * (view.view_projection * vec4(p, 1.0)).w;
    vec3 offset_normal = dot(n, to_light) >= 0.0 ? normalize(n) : -normalize(n);
    float cos_theta = dot(offset_normal, to_light);
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    vec4 clip = view.view_projection * vec4(p + offset_normal * (shadow_normal_offset * texel_world * sin_theta + lift), 1.0);
    vec3 ndc = clip.xyz / clip.w;
    vec2 tile_uv = clamp(ndc.xy * 0.5 + 0.5, vec2(view.texel.y), vec2(1.0 - view.texel.y));
    float depth = ndc.z * 0.5 + 0.5;
    if (depth >= 1.0) return 1.0;
    return texture(shadow_atlas, vec3(view.atlas_rect.xy + tile_uv * view.atlas_rect.zw, depth));
}

// Irradiance at p from light i on a surface with normal n: E = I cos(theta) / d^2 (point, spot),
// E = E_perp cos(theta) (directional), times shadow and spot/range windows. l: unit direction to the light.
// n may be a voxel's mean normal: dot(n, l) is then the mean of its fragments' cosines; `lift`
// and `camera_cascades` as for shadow_visibility (0 and true for a point the camera sees).
vec3 light_irradiance(int i, vec3 p, vec3 n, float lift, bool camera_cascades, out vec3 l) {
    Light light = lights[i];
    int type = int(light.position_type.w);
    float attenuation;
    if (type == LIGHT_DIRECTIONAL) {
        l = -light.direction_range.xyz;
        attenuation = 1.0;
    } else {
        vec3 to_light = light.position_type.xyz - p;
        float d2 = max(dot(to_light, to_light), 1e-8);
        float d = sqrt(d2);
        l = to_light / d;
        attenuation = 1.0 / d2; // inverse-square law
        float range = light.direction_range.w;
        if (range > 0.0) {
            float x = clamp(1.0 - pow(d / range, 4.0), 0.0, 1.0);
            attenuation *= x * x; // smooth window reaching 0 at the range
        }
        if (type == LIGHT_SPOT) {
            float c = dot(-l, light.direction_range.xyz);
            // smoothstep(cos outer, cos inner, c), defined also where the two angles are equal
            float t = clamp((c - light.shape.y) / max(light.shape.x - light.shape.y, 1e-6), 0.0, 1.0);
            attenuation *= t * t * (3.0 - 2.0 * t);
        }
    }
    float cos_theta = dot(n, l);
    if (cos_theta <= 0.0 || attenuation <= 0.0) return vec3(0.0);
    return light.intensity_shadow.rgb * attenuation * cos_theta * shadow_visibility(light, p, n, l, lift, camera_cascades);
}
