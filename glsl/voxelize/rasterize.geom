#version 450 core
// Voxelization, geometry stage: project each triangle along its dominant normal axis onto an
// N x N viewport over the cube of its job's level and dilate it by half a pixel (conservative
// rasterization, OpenGL Insights ch. 22) so thin and grazing triangles leave no holes;
// attributes are extrapolated with the barycentric coordinates of the dilated corners. The
// triangle is clipped (gl_ClipDistance) to the voxels the job writes grown by a voxel, so
// fragments outside a slab are never shaded (the fragment stage keeps the exact test).
#include "lib/voxel.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in vec3 vs_position[];
in vec3 vs_normal[];
flat in uint vs_material[];
flat in ivec4 vs_voxels_min[];
flat in ivec3 vs_voxels_max[];
out vec3 gs_position;
out vec3 gs_normal;
#ifdef VERTEX_EXTRAS
in vec3 vs_color[];
in vec4 vs_map_coordinates01[];
in vec4 vs_map_coordinates23[];
out vec3 gs_color;
out vec4 gs_map_coordinates01;
out vec4 gs_map_coordinates23;
#else
in vec2 vs_texcoord[];
out vec2 gs_texcoord;
#endif
flat out vec4 gs_pixel_bounds;  // the undilated triangle's bounding box in pixels, grown by half a pixel
flat out vec3 gs_edges[3];      // the undilated triangle's edge lines in NDC: line.xy . p + line.z > 0 inside
flat out uint gs_material;
flat out ivec4 gs_voxels_min;   // the job's voxels [min, max) in its level's coordinates; w: the level
flat out ivec3 gs_voxels_max;
out gl_PerVertex {
    vec4 gl_Position;
    float gl_ClipDistance[6];  // the voxels written, grown by a voxel: >= 0 inside each of its 6 planes
};

// Voxel-space coordinates swizzled so the dominant axis becomes depth.
vec3 project(vec3 uvw, int axis) {
    if (axis == 0) return uvw.yzx;
    if (axis == 1) return uvw.zxy;
    return uvw.xyz;
}

void main() {
    vec3 face_normal = cross(vs_position[1] - vs_position[0], vs_position[2] - vs_position[0]);
    if (dot(face_normal, face_normal) == 0.0) return;  // degenerate triangle
    int axis = dominant_axis(face_normal);
    int voxelize_level = vs_voxels_min[0].w;
    ivec3 voxelized_min = vs_voxels_min[0].xyz, voxelized_max = vs_voxels_max[0];

    vec2 corner[3];
    float depth[3];
    for (int i = 0; i < 3; ++i) {
        vec3 q = project(level_uvw(vs_position[i], voxelize_level), axis);
        corner[i] = q.xy * 2.0 - 1.0;   // NDC
        depth[i] = q.z * 2.0 - 1.0;
    }
    float half_pixel = 1.0 / float(voxel_grid);  // half a pixel in NDC

    // Orient the triangle counter-clockwise in 2D so "outward" is well defined.
    float area = (corner[1].x - corner[0].x) * (corner[2].y - corner[0].y) - (corner[2].x - corner[0].x) * (corner[1].y - corner[0].y);
    int order[3] = area >= 0.0 ? int[3](0, 1, 2) : int[3](0, 2, 1);

    vec2 lo = min(corner[0], min(corner[1], corner[2])) - half_pixel;
    vec2 hi = max(corner[0], max(corner[1], corner[2])) + half_pixel;
    vec4 bounds = vec4((lo * 0.5 + 0.5) * float(voxel_grid), (hi * 0.5 + 0.5) * float(voxel_grid));

    // Edge lines shifted outward by half a pixel along the worst-case (diagonal) direction.
    vec3 undilated[3], edge[3];
    for (int i = 0; i < 3; ++i) {
        vec2 p0 = corner[order[i]], p1 = corner[order[(i + 1) % 3]];
        vec3 line = cross(vec3(p0, 1.0), vec3(p1, 1.0));   // line through p0, p1: line.xy . p + line.z = 0
        undilated[i] = line;
        line.z += half_pixel * (abs(line.x) + abs(line.y)); // inside is line . p > 0 for ccw order
        edge[i] = line;
    }
    mat3 to_barycentric = inverse(mat3(vec3(corner[0], 1.0), vec3(corner[1], 1.0), vec3(corner[2], 1.0)));
    for (int k = 0; k < 3; ++k) {
        // Dilated corner k: intersection of the shifted edges meeting at the original corner.
        int i = order[k];
        vec3 x = cross(edge[(k + 2) % 3], edge[k]);
        vec2 dilated = abs(x.z) > 1e-12 ? x.xy / x.z : corner[i];
        vec3 w = to_barycentric * vec3(dilated, 1.0);
        gs_position = w.x * vs_position[0] + w.y * vs_position[1] + w.z * vs_position[2];
        gs_normal = w.x * vs_normal[0] + w.y * vs_normal[1] + w.z * vs_normal[2];
#ifdef VERTEX_EXTRAS
        gs_color = w.x * vs_color[0] + w.y * vs_color[1] + w.z * vs_color[2];
        gs_map_coordinates01 = w.x * vs_map_coordinates01[0] + w.y * vs_map_coordinates01[1] + w.z * vs_map_coordinates01[2];
        gs_map_coordinates23 = w.x * vs_map_coordinates23[0] + w.y * vs_map_coordinates23[1] + w.z * vs_map_coordinates23[2];
#else
        gs_texcoord = w.x * vs_texcoord[0] + w.y * vs_texcoord[1] + w.z * vs_texcoord[2];
#endif
        gs_pixel_bounds = bounds;
        gs_edges = undilated;
        gs_material = vs_material[0];
        gs_voxels_min = vs_voxels_min[0];
        gs_voxels_max = voxelized_max;
        vec3 local = level_uvw(gs_position, voxelize_level) * float(voxel_grid);
        vec3 above_min = local - vec3(voxelized_min - 1), below_max = vec3(voxelized_max + 1) - local;
        for (int a = 0; a < 3; ++a) {
            gl_ClipDistance[2 * a] = above_min[a];
            gl_ClipDistance[2 * a + 1] = below_max[a];
        }
        gl_Position = vec4(dilated, w.x * depth[0] + w.y * depth[1] + w.z * depth[2], 1.0);
        EmitVertex();
    }
    EndPrimitive();
}
