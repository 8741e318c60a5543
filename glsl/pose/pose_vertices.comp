#version 450 core
// Poses the vertices of one draw (engine/passes/pose.py), read from its mesh's rest copy in the
// pool and written into the draw's own copy: first the morph targets, blended by the draw's
// weights (glTF 2.0, 3.7.2.2: p = p0 + sum_t w_t dp_t, and so normals and tangents' xyz), then,
// for a skinned mesh, linear blend skinning into the world (3.7.3.3: p' = sum_i w_i J_i p,
// normals by the cofactors of sum_i w_i J_i, tangents by its 3x3 part). Texture coordinates
// and colours are copied as they are. Each posed vertex's position of the frame before is kept
// (temporal anti-aliasing's motion: the G-buffer reads it): the copy's position before it is
// written over, or, where there is no frame before (`fresh`), the new one; `holding` copies the
// copy's position alone (a draw posed at the last frame and not since has not moved).
#include "engine_constants.glsl"
#include "lib/normal_transform.glsl"

layout(local_size_x = LIST_GROUP) in;
layout(std430, binding = SSBO_POSE_VERTICES) buffer Vertices { float vertices[]; };
layout(std430, binding = SSBO_POSE_INFLUENCES) readonly buffer Influences { PoseInfluence influences[]; };
layout(std430, binding = SSBO_POSE_TARGETS) readonly buffer Targets { vec4 displacements[]; };
layout(std430, binding = SSBO_POSE_MATRICES) readonly buffer Matrices { mat4 joint_matrices[]; };
layout(std430, binding = SSBO_POSE_WEIGHTS) readonly buffer Weights { float target_weights[]; };
layout(std430, binding = SSBO_POSE_PREVIOUS) writeonly buffer Previous { vec4 previous_positions[]; };  // per pool vertex

uniform uint vertex_count;
uniform uint rest_first;       // the mesh's first vertex in the pool
uniform uint posed_first;      // the draw's own copy's
uniform uint influence_sets;   // PoseInfluences per vertex (0: not skinned)
uniform uint target_count;     // morph targets (0: none)
uniform uint first_matrix;     // the draw's joint matrices in joint_matrices
uniform uint first_weight;     // its target weights in target_weights
uniform bool fresh;            // no frame before: the previous position is the new one
uniform bool holding;          // no new pose: the previous position becomes the copy's

vec3 read3(uint at) { return vec3(vertices[at], vertices[at + 1u], vertices[at + 2u]); }

void write3(uint at, vec3 value) {
    vertices[at] = value.x;
    vertices[at + 1u] = value.y;
    vertices[at + 2u] = value.z;
}

void main() {
    uint vertex = gl_GlobalInvocationID.x;
    if (vertex >= vertex_count) return;
    uint rest = (rest_first + vertex) * uint(VERTEX_FLOATS);
    uint posed = (posed_first + vertex) * uint(VERTEX_FLOATS);
    if (holding || !fresh) previous_positions[posed_first + vertex] = vec4(read3(posed), 1.0);
    if (holding) return;
    for (uint k = 0u; k < uint(VERTEX_FLOATS); ++k) vertices[posed + k] = vertices[rest + k];
    vec3 position = read3(rest);
    vec3 normal = read3(rest + uint(VERTEX_NORMAL_AT));
    vec3 tangent = read3(rest + uint(VERTEX_TANGENT_AT));
    for (uint t = 0u; t < target_count; ++t) {
        float weight = target_weights[first_weight + t];
        uint at = 3u * (t * vertex_count + vertex);
        position += weight * displacements[at].xyz;
        normal += weight * displacements[at + 1u].xyz;
        tangent += weight * displacements[at + 2u].xyz;
    }
    if (influence_sets > 0u) {
        mat4 skin = mat4(0.0);
        for (uint s = 0u; s < influence_sets; ++s) {
            PoseInfluence influence = influences[vertex * influence_sets + s];
            for (int i = 0; i < 4; ++i) {
                if (influence.weights[i] != 0.0) skin += influence.weights[i] * joint_matrices[first_matrix + influence.joints[i]];
            }
        }
        position = (skin * vec4(position, 1.0)).xyz;
        normal = normal_transform(mat3(skin)) * normal;
        tangent = mat3(skin) * tangent;
    }
    float normal_length = length(normal);
    float tangent_length = length(tangent);
    write3(posed, position);
    if (fresh) previous_positions[posed_first + vertex] = vec4(position, 1.0);
    write3(posed + uint(VERTEX_NORMAL_AT), normal_length > 0.0 ? normal / normal_length : vec3(0.0, 0.0, 1.0));
    write3(posed + uint(VERTEX_TANGENT_AT), tangent_length > 0.0 ? tangent / tangent_length : tangent);
}
