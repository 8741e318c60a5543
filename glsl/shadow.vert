#version 450 core
// Shadow map: depth of the scene seen from one light view (a cube face, a spot or a sun).
in vec3 in_position;
in vec3 in_normal;
uniform mat4 model;
uniform mat4 view_projection;

void main() {
    gl_Position = view_projection * model * vec4(in_position, 1.0);
}
