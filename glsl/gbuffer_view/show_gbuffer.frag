#version 450 core
// G-buffer inspection: albedo, normal encoded as 0.5 n + 0.5, or view depth / far plane.
#include "lib/gbuffer.glsl"
#include "lib/camera.glsl"

uniform int view;  // VIEW_* (engine/core/constants.py: SHADER_ENUMS)
uniform float far_plane;
layout(location = 0) out vec4 out_value;

void main() {
    Surface s = read_gbuffer(ivec2(gl_FragCoord.xy));
    if (!s.covered) { out_value = vec4(0.0); return; }
    if (view == VIEW_ALBEDO) out_value = vec4(s.albedo, 1.0);
    else if (view == VIEW_NORMAL) out_value = vec4(0.5 * s.normal + 0.5, 1.0);
    else out_value = vec4(vec3(dot(s.position - camera.position.xyz, camera.forward.xyz) / far_plane), 1.0);
}
