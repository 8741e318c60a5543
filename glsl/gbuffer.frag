#version 450 core
// G-buffer: position, normal + roughness, albedo + metalness, emission + dielectric F0.
in vec3 world_position;
in vec3 world_normal;
uniform vec3 albedo;
uniform float roughness;
uniform float metalness;
uniform float dielectric_f0;
uniform vec3 emission;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;
layout(location = 3) out vec4 out_emission;

void main() {
    vec3 n = normalize(world_normal);
    // Surfaces are one-sided emitters but two-sided reflectors: shade the side we see.
    out_position = vec4(world_position, 1.0);
    out_normal = vec4(gl_FrontFacing ? n : -n, roughness);
    out_albedo = vec4(albedo, metalness);
    out_emission = vec4(gl_FrontFacing ? emission : vec3(0.0), dielectric_f0);
}
