#version 450 core
// Voxelization, vertex stage: world-space triangle corners, normals and texture coordinates.
in vec3 in_position;
in vec3 in_normal;
in vec2 in_texcoord;
uniform mat4 model;
uniform mat3 normal_matrix;
out vec3 vs_position;
out vec3 vs_normal;
out vec2 vs_texcoord;

void main() {
    vs_position = (model * vec4(in_position, 1.0)).xyz;
    vs_normal = normal_matrix * in_normal;
    vs_texcoord = in_texcoord;
}
