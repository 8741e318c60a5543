// The camera the image is seen from (renderer.FrameCamera): perspective rays leave
// camera_position; orthographic ones run along camera_forward, from the plane through it.
uniform vec3 camera_position;
uniform vec3 camera_forward;
uniform bool camera_orthographic;
uniform mat4 inverse_view_projection;

// The unit direction from surface point p towards the camera.
vec3 to_camera(vec3 p) {
    return camera_orthographic ? -camera_forward : normalize(camera_position - p);
}

// How far p lies from the camera along the rays that see it.
float camera_distance(vec3 p) {
    return camera_orthographic ? dot(p - camera_position, camera_forward) : distance(camera_position, p);
}

// The camera ray through a point of the image (x and y in -1..1): where it starts on the near
// plane, and its unit direction.
void camera_ray(vec2 ndc, out vec3 origin, out vec3 direction) {
    vec4 near = inverse_view_projection * vec4(ndc, -1.0, 1.0);
    vec4 far = inverse_view_projection * vec4(ndc, 1.0, 1.0);
    origin = near.xyz / near.w;
    direction = normalize(far.xyz / far.w - origin);
}
