#version 450 core
// Temporal anti-aliasing: this frame's image, seen through a point of the pixel that moves from
// frame to frame (engine/passes/temporal.py), blended into the history of the frames before.
// Each pixel finds where its surface point was in the last frame's image (the camera's motion,
// and the point's own: the G-buffer's GBUF_PREVIOUS), reads the history there, clamps it to the range of this
// frame's 3x3 neighbourhood (what the history holds that this frame no longer shows), and
// drops it where that place saw another surface (disoccluded: its distance from the camera
// differs) or lies off the image. With n the frames the pixel's history holds (its a, at most
// TEMPORAL_FRAMES): result = history + (current - history) / n, the mean of a still pixel's
// last n samples.
#include "engine_constants.glsl"
#include "lib/camera.glsl"

layout(binding = TEX_HDR_INPUT) uniform sampler2D current_image;
layout(binding = TEX_GBUF_POSITION) uniform sampler2D gbuffer_position;  // world position, a > 0: a surface
layout(binding = TEX_GBUF_PREVIOUS) uniform sampler2D gbuffer_previous;  // where it was at the frame before
layout(binding = TEX_HISTORY) uniform sampler2D history;                 // rgb, a = frames it holds
layout(binding = TEX_HISTORY_DISTANCE) uniform sampler2D history_distance;
layout(location = 0) out vec4 history_out;
layout(location = 1) out float history_distance_out;
uniform mat4 centred_view_projection;   // this frame's through the pixels' centres (no jitter)
uniform mat4 previous_view_projection;  // the last frame's, through the pixels' centres
uniform vec3 previous_eye;
uniform bool history_valid;             // false: the first frame, or the view was resized

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(current_image, 0);
    vec4 current = texelFetch(current_image, pixel, 0);
    // The range of the 3x3 pixels around it.
    vec3 low = current.rgb, high = current.rgb;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = texelFetch(current_image, clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1), 0).rgb;
            low = min(low, c);
            high = max(high, c);
        }
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    bool surface = p.w > 0.0;
    vec3 is, was;  // the point this pixel sees, and where it was at the last frame
    if (surface) {
        is = p.xyz;
        was = texelFetch(gbuffer_previous, pixel, 0).xyz;
    } else {  // the sky: a point far along the pixel's ray, which moves with the camera's turn alone
        vec3 origin, direction;
        camera_ray((vec2(pixel) + 0.5) / vec2(size) * 2.0 - 1.0, origin, direction);
        is = camera.position.xyz + direction * 1e6;
        was = previous_eye + direction * 1e6;
    }
    // Its motion across the image without the jitter (the point seen is the jittered ray's,
    // between pixel centres), from the pixel's centre.
    vec4 now = centred_view_projection * vec4(is, 1.0), clip = previous_view_projection * vec4(was, 1.0);
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size) + 0.5 * (clip.xy / clip.w - now.xy / now.w);
    float frames = 0.0;
    vec3 held = current.rgb;
    if (history_valid && clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)))) {
        // What the 3x3 history pixels around the place saw: the point's surface in one of them at
        // least (a small object's edge moves between pixels with the jitter), else it was hidden.
        float expected = surface ? distance(previous_eye, was) : 0.0;
        ivec2 place = ivec2(uv * vec2(size));
        float tolerance = DISOCCLUSION_TOLERANCE * expected;
        bool seen = abs(texelFetch(history_distance, clamp(place, ivec2(0), size - 1), 0).r - expected) <= tolerance;
        for (int k = 0; k < 9 && !seen; ++k) {
            ivec2 around = clamp(place + ivec2(k % 3 - 1, k / 3 - 1), ivec2(0), size - 1);
            seen = abs(texelFetch(history_distance, around, 0).r - expected) <= tolerance;
        }
        if (seen) {
            vec4 h = textureLod(history, uv, 0.0);
            held = clamp(h.rgb, low, high);
            frames = h.a;
        }
    }
    frames = min(frames + 1.0, float(TEMPORAL_FRAMES));
    history_out = vec4(mix(held, current.rgb, 1.0 / frames), frames);
    history_distance_out = surface ? distance(camera.position.xyz, p.xyz) : 0.0;
}
