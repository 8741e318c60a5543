#version 450 core
// G-buffer geometry: world position, normal, texture coordinates and, for a material with a
// normal map (NORMAL_MAP defined), tangent of every visible surface; for a mesh with vertex
// colours or a second texture coordinate set, or a material that transforms its texture
// coordinates (VERTEX_EXTRAS), those. Without them they are
// not passed on: on llvmpipe every output of this stage costs each triangle's setup time.
in vec3 in_position;
in vec3 in_normal;
in vec2 in_texcoord;
uniform mat4 model;
uniform mat3 normal_matrix;
uniform mat4 view_projection;
out vec3 world_position;
out vec3 world_normal;
out vec2 texcoord;
#ifdef NORMAL_MAP
in vec4 in_tangent;
out vec4 world_tangent;
#endif
#ifdef VERTEX_EXTRAS
in vec3 in_color;
in vec2 in_texcoord1;
out vec3 vertex_color;
out vec2 texcoord1;
#endif

void main() {
    vec4 p = model * vec4(in_position, 1.0);
    world_position = p.xyz;
    world_normal = normal_matrix * in_normal;
#ifdef NORMAL_MAP
    world_tangent = vec4(mat3(model) * in_tangent.xyz, in_tangent.w);
#endif
    texcoord = in_texcoord;
#ifdef VERTEX_EXTRAS
    vertex_color = in_color;
    texcoord1 = in_texcoord1;
#endif
    gl_Position = view_projection * p;
}
