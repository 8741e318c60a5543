#version 450 core
// Shadow map: depth of the scene seen from one light view (a cube face, a spot or a sun).
in vec3 in_position;
in vec2 in_texcoord;
in vec2 in_texcoord1;
uniform mat4 model;
uniform mat4 view_projection;
out vec2 texcoord;
out vec2 texcoord1;

void main() {
    texcoord = in_texcoord;
    texcoord1 = in_texcoord1;
    gl_Position = view_projection * model * vec4(in_position, 1.0);
}
