#version 450 core
// Voxelization, vertex stage: world-space triangle corners.
in vec3 in_position;
in vec3 in_normal;
uniform mat4 model;
uniform mat3 normal_matrix;
out vec3 vs_position;
out vec3 vs_normal;

void main() {
    vs_position = (model * vec4(in_position, 1.0)).xyz;
    vs_normal = normal_matrix * in_normal;
}
