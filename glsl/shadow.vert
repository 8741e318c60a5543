#version 450 core
// Shadow map: depth of the scene seen from one light view (a cube face, a spot or a sun).
in vec3 in_position;
in vec2 in_texcoord;
uniform mat4 model;
uniform mat4 view_projection;
out vec2 texcoord;

void main() {
    texcoord = in_texcoord;
    gl_Position = view_projection * model * vec4(in_position, 1.0);
}
