#version 450 core
// Voxelization, vertex stage: world-space triangle corners, normals and texture coordinates
// (and vertex colours and a second set of texture coordinates where VERTEX_EXTRAS).
in vec3 in_position;
in vec3 in_normal;
in vec2 in_texcoord;
uniform mat4 model;
uniform mat3 normal_matrix;
out vec3 vs_position;
out vec3 vs_normal;
out vec2 vs_texcoord;
#ifdef VERTEX_EXTRAS
in vec3 in_color;
in vec2 in_texcoord1;
out vec3 vs_color;
out vec2 vs_texcoord1;
#endif

void main() {
    vs_position = (model * vec4(in_position, 1.0)).xyz;
    vs_normal = normal_matrix * in_normal;
    vs_texcoord = in_texcoord;
#ifdef VERTEX_EXTRAS
    vs_color = in_color;
    vs_texcoord1 = in_texcoord1;
#endif
}
