#version 450 core
// G-buffer geometry: world position, normal, tangent and texture coordinates of every visible surface.
in vec3 in_position;
in vec3 in_normal;
in vec2 in_texcoord;
in vec4 in_tangent;
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
out vec4 world_tangent;
out vec2 texcoord;

void main() {
    vec4 p = model * vec4(in_position, 1.0);
    world_position = p.xyz;
    world_normal = normal_matrix * in_normal;
    world_tangent = vec4(mat3(model) * in_tangent.xyz, in_tangent.w);
    texcoord = in_texcoord;
    gl_Position = view_projection * p;
}
