// Direct light from emissive surfaces (engine/scene/emitters.py): exact per triangle by Lambert's
// polygon formula. Shadowed per patch by a visibility cone through the face views at the
// voxels (emitter_light/light_voxels.comp), whose visible fraction the pixels interpolate.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_EMITTER_TRIANGLES) readonly buffer EmitterTriangles { EmitterTriangle emitter_triangles[]; };
layout(std430, binding = SSBO_EMITTER_PATCHES) readonly buffer EmitterPatches { EmitterPatch emitter_patches[]; };
uniform int emitter_patch_count;

// One edge's term of Lambert's formula: the angle between corners u and w (seen from p) times
// n . normalize(u x w).
float edge_term(vec3 u, vec3 w, vec3 n) {
    vec3 normal = cross(u, w);
    float sine = length(normal);
    return sine > 0.0 ? atan(sine, dot(u, w)) * dot(n, normal) / sine : 0.0;
}

// The part of edge u -> w (corners seen from p, heights hu, hw over p's horizon) above the
// horizon, and where it crosses it: `leaving` from above to below, `entering` the other way.
float clipped_edge_term(vec3 u, vec3 w, float hu, float hw, vec3 n, inout vec3 leaving, inout vec3 entering) {
    if (hu > 0.0 && hw > 0.0) return edge_term(u, w, n);
    if (hu <= 0.0 && hw <= 0.0) return 0.0;
    vec3 crossing = normalize(u + (w - u) * (hu / (hu - hw)));
    if (hu > 0.0) { leaving = crossing; return edge_term(u, crossing, n); }
    entering = crossing;
    return edge_term(crossing, w, n);
}

// Irradiance at p (unit normal n) from a one-sided Lambertian triangle of radiance L, over the
// part of it above p's horizon (the triangle clipped by the plane through p normal to n, whose
// cut adds the edge along the horizon from where the outline leaves it to where it enters):
//   E = L / 2 sum_edges angle(u_i, u_i+1) n . normalize(u_i x u_i+1)   (Lambert's formula)
// with u_i the corners seen from p; zero where p lies behind the triangle's front side (or in
// its plane, a corner included).
vec3 triangle_irradiance(vec3 p, vec3 n, EmitterTriangle t) {
    if (dot(cross(t.b.xyz - t.a.xyz, t.c.xyz - t.a.xyz), t.a.xyz - p) >= 0.0) return vec3(0.0);
    vec3 a = normalize(t.a.xyz - p), b = normalize(t.b.xyz - p), c = normalize(t.c.xyz - p);
    float ha = dot(n, a), hb = dot(n, b), hc = dot(n, c);
    vec3 leaving = vec3(0.0), entering = vec3(0.0);
    float projected_solid_angle = clipped_edge_term(a, b, ha, hb, n, leaving, entering)
                                + clipped_edge_term(b, c, hb, hc, n, leaving, entering)
                                + clipped_edge_term(c, a, hc, ha, n, leaving, entering);
    if ((ha > 0.0) != (hb > 0.0) || (hb > 0.0) != (hc > 0.0)) projected_solid_angle += edge_term(leaving, entering, n);
    return t.radiance.rgb * (0.5 * abs(projected_solid_angle));
}

// Irradiance at p (unit normal n) from the triangles of one patch, unshadowed; none where p
// lies behind the whole patch or the patch below p's horizon.
vec3 patch_irradiance(vec3 p, vec3 n, EmitterPatch e) {
    vec3 irradiance = vec3(0.0);
    if (dot(e.plane.xyz, p - e.sphere.xyz) < -e.plane.w || dot(n, e.sphere.xyz - p) < -e.sphere.w) return irradiance;
    for (uint k = e.triangles.x; k < e.triangles.x + e.triangles.y; ++k)
        irradiance += triangle_irradiance(p, n, emitter_triangles[k]);
    return irradiance;
}

// Irradiance at p (unit normal n) from every emitter, unshadowed.
vec3 emitter_irradiance(vec3 p, vec3 n) {
    vec3 irradiance = vec3(0.0);
    for (int i = 0; i < emitter_patch_count; ++i) irradiance += patch_irradiance(p, n, emitter_patches[i]);
    return irradiance;
}
