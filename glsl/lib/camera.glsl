// The camera the image is seen from (renderer.FrameCamera, written once a frame): perspective
// rays leave its position; orthographic ones run along its forward direction, from the plane
// through it.
#include "engine_constants.glsl"

layout(std140, binding = UBO_CAMERA) uniform CameraBlock { FrameCamera camera; };

bool camera_orthographic() {
    return camera.position.w != 0.0;
}

// The unit direction from surface point p towards the camera.
vec3 to_camera(vec3 p) {
    return camera_orthographic() ? -camera.forward.xyz : normalize(camera.position.xyz - p);
}

// How far p lies from the camera along the rays that see it.
float camera_distance(vec3 p) {
    return camera_orthographic() ? dot(p - camera.position.xyz, camera.forward.xyz) : distance(camera.position.xyz, p);
}

// The camera ray through a point of the image (x and y in -1..1): where it starts on the near
// plane, and its unit direction.
void camera_ray(vec2 ndc, out vec3 origin, out vec3 direction) {
    vec4 near = camera.inverse_view_projection * vec4(ndc, -1.0, 1.0);
    vec4 far = camera.inverse_view_projection * vec4(ndc, 1.0, 1.0);
    origin = near.xyz / near.w;
    direction = normalize(far.xyz / far.w - origin);
}
