#version 450 core
// A draw list's culling: for each of its views and each of the view's items (a draw's cluster),
// the cluster's world box (its bounds' eight corners through the draw's world matrix) tested
// against the view: outside the view's frustum (all corners beyond one clip plane) or apart from
// its world box, it is left out; otherwise the cluster's command draws one more instance, its
// value the draw and the view (lib/draws.glsl). The order of a command's instances follows
// the atomics: what is drawn does not depend on it (the depth test, the voxels' integer sums).
#define HELD_DRAWS
#include "lib/draws.glsl"
#include "lib/draw_views.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_DRAW_ITEMS) readonly buffer DrawItems { uvec4 items[]; };  // draw, cluster, command
layout(std430, binding = SSBO_CLUSTERS) readonly buffer Clusters { Cluster clusters[]; };
layout(std430, binding = SSBO_DRAW_COMMANDS) buffer DrawCommands { uint commands[]; };  // 5 per command
layout(std430, binding = SSBO_DRAW_INSTANCES) writeonly buffer DrawInstances { uint instances[]; };

void main() {
    uint view_index = gl_GlobalInvocationID.y;
    DrawView view = views[view_index];
    if (gl_GlobalInvocationID.x >= view.items.y) return;
    uvec4 item = items[view.items.x + gl_GlobalInvocationID.x];
    mat4x3 world = value_world(item.x);
    Cluster cluster = clusters[item.y];
    uvec3 below = uvec3(0u), above = uvec3(0u);  // the corners beyond each plane -w, w
    vec3 lo = vec3(3.4e38), hi = vec3(-3.4e38);
    for (int corner = 0; corner < 8; ++corner) {
        vec3 local = mix(cluster.lo.xyz, cluster.hi.xyz, vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1));
        vec3 p = world * vec4(local, 1.0);
        lo = min(lo, p);
        hi = max(hi, p);
        vec4 clip = view.view_projection * vec4(p, 1.0);
        below += uvec3(lessThan(clip.xyz, vec3(-clip.w)));
        above += uvec3(greaterThan(clip.xyz, vec3(clip.w)));
    }
    if ((view.items.z & DRAW_TEST_FRUSTUM) != 0u && (any(equal(below, uvec3(8u))) || any(equal(above, uvec3(8u))))) return;
    if ((view.items.z & DRAW_TEST_BOX) != 0u && (any(greaterThan(lo, view.box_max.xyz)) || any(lessThan(hi, view.box_min.xyz)))) return;
    uint command = item.z;
    uint slot = atomicAdd(commands[5u * command + 1u], 1u);
    instances[commands[5u * command + 4u] + slot] = item.x | (view_index << DRAW_VIEW_SHIFT);
}
