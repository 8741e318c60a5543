#version 450 core
// Temporal anti-aliasing: this frame's image, seen through a point of the pixel that moves from
// frame to frame (engine/passes/temporal.py), blended into the history of the frames before.
// Each pixel finds where its surface point was in the last frame's image (the camera's motion,
// and the point's own: the G-buffer's GBUF_PREVIOUS), reads the history there, clamps it to
// the range of the pixel and its four edge neighbours in this frame (what the history holds
// that this frame no longer shows), and drops it where none of the 3x3 history pixels around
// that place saw the same surface (disoccluded: its distance from the camera differs) or where
// it lies off the image. With n the frames the pixel's history holds (its a, at most
// TEMPORAL_FRAMES): result = history + (current - history) / n, the mean of a still pixel's
// last n samples.
#include "engine_constants.glsl"
#include "lib/camera.glsl"

layout(local_size_x = SCREEN_GROUP, local_size_y = SCREEN_GROUP) in;

layout(binding = TEX_HDR_INPUT) uniform sampler2D current_image;
layout(binding = TEX_GBUF_POSITION) uniform sampler2D gbuffer_position;  // world position, a > 0: a surface
layout(binding = TEX_GBUF_PREVIOUS) uniform sampler2D gbuffer_previous;  // where it was at the frame before
layout(binding = TEX_HISTORY) uniform sampler2D history;                 // rgb, a = frames it holds
layout(binding = TEX_HISTORY_DISTANCE) uniform sampler2D history_distance;
layout(binding = IMG_HISTORY_OUT, rgba32f) uniform writeonly image2D history_out;
layout(binding = IMG_HISTORY_DISTANCE_OUT, r32f) uniform writeonly image2D history_distance_out;
uniform mat4 centred_view_projection;   // this frame's through the pixels' centres (no jitter)
uniform mat4 previous_view_projection;  // the last frame's, through the pixels' centres
uniform mat4 sky_reprojection;         // a far point through this frame's centred view to the last frame's clip space, as a direction
uniform vec3 previous_eye;
uniform bool history_valid;             // false: the first frame, or the view was resized

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(current_image, 0);
    if (any(greaterThanEqual(pixel, size))) return;
    vec4 current = texelFetch(current_image, pixel, 0);
    // The range of the pixel and its four edge neighbours.
    vec3 low = current.rgb, high = current.rgb;
    const ivec2 NEIGHBOURS[4] = ivec2[](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));
    for (int k = 0; k < 4; ++k) {
        vec3 c = texelFetch(current_image, clamp(pixel + NEIGHBOURS[k], ivec2(0), size - 1), 0).rgb;
        low = min(low, c);
        high = max(high, c);
    }
    // Where the point this pixel sees was in the last frame's image, and where it is in this
    // one without the jitter (the point seen is the jittered ray's, between pixel centres): a
    // surface's from the G-buffer; the sky's, a direction, moves with the camera's turn alone.
    vec2 centre = (vec2(pixel) + 0.5) / vec2(size);
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    bool surface = p.w > 0.0;
    vec3 was = texelFetch(gbuffer_previous, pixel, 0).xyz;
    vec4 now = centred_view_projection * vec4(p.xyz, 1.0);
    vec4 clip = surface ? previous_view_projection * vec4(was, 1.0) : sky_reprojection * vec4(centre * 2.0 - 1.0, 1.0, 1.0);
    vec2 moved = 0.5 * (clip.xy / clip.w - (surface ? now.xy / now.w : centre * 2.0 - 1.0));
    vec2 uv = centre + moved;
    float frames = 0.0;
    vec3 held = current.rgb;
    if (history_valid && clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)))) {
        // What the 3x3 history pixels around the place saw: the point's surface in one of
        // them at least (a small object's edge moves between
        // pixels with the jitter), else it was hidden.
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
    imageStore(history_out, pixel, vec4(mix(held, current.rgb, 1.0 / frames), frames));
    imageStore(history_distance_out, pixel, vec4(surface ? distance(camera.position.xyz, p.xyz) : 0.0));
}
