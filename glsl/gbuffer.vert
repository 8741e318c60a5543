#version 450 core
// G-buffer geometry: world position and normal of every visible surface.
in vec3 in_position;
in vec3 in_normal;
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;

void main() {
    vec4 p = model * vec4(in_position, 1.0);
    world_position = p.xyz;
    world_normal = normal_matrix * in_normal;
    gl_Position = view_projection * p;
}
