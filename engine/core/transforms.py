"""4x4 matrices for column vectors (p' = M @ p), float64 numpy; upload with `gl_bytes`."""
import math

import numpy as np
import pyrr


def euler_rotations_deg(angles):
    """3x3 rotations of (k, 3) angles [x, y, z] in degrees about the fixed axes, applied x, then
    y, then z (R = Rz Ry Rx); each a right-handed rotation (counter-clockwise looking down the
    axis). (k, 3, 3)."""
    ax, ay, az = np.radians(np.asarray(angles, float).reshape(-1, 3)).T
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    one, zero = np.ones(len(ax)), np.zeros(len(ax))
    rx = np.stack([one, zero, zero, zero, cx, -sx, zero, sx, cx], axis=1).reshape(-1, 3, 3)
    ry = np.stack([cy, zero, sy, zero, one, zero, -sy, zero, cy], axis=1).reshape(-1, 3, 3)
    rz = np.stack([cz, -sz, zero, sz, cz, zero, zero, zero, one], axis=1).reshape(-1, 3, 3)
    return rz @ ry @ rx


def rotate_euler_deg(angles):
    """The 4x4 rotation by angles [x, y, z] in degrees (euler_rotations_deg)."""
    m = np.eye(4)
    m[:3, :3] = euler_rotations_deg(angles)[0]
    return m


def compose(translation, rotation_deg, scale_xyz):
    """T * R * S."""
    return compose_many(translation, rotation_deg, scale_xyz)[0]


def compose_many(translations, rotations_deg, scales):
    """T * R * S of each row of (k, 3) translations, rotation angles (euler_rotations_deg) and
    scales, as (k, 4, 4)."""
    t = np.asarray(translations, float).reshape(-1, 3)
    matrices = np.zeros((len(t), 4, 4))
    matrices[:, :3, :3] = euler_rotations_deg(rotations_deg) * np.asarray(scales, float).reshape(-1, 1, 3)  # R S: columns scaled
    matrices[:, :3, 3] = t
    matrices[:, 3, 3] = 1.0
    return matrices


def perspective(vertical_fov_deg, aspect, near, far):
    return pyrr.matrix44.create_perspective_projection(vertical_fov_deg, aspect, near, far, dtype=np.float64).T


def orthographic(half_width, half_height, near, far):
    return pyrr.matrix44.create_orthogonal_projection(-half_width, half_width, -half_height, half_height, near, far, dtype=np.float64).T


def look_at(eye, target, up):
    return pyrr.matrix44.create_look_at(np.asarray(eye, float), np.asarray(target, float), np.asarray(up, float), dtype=np.float64).T


def transform_points(m, points):
    p = np.asarray(points, float)
    return p @ m[:3, :3].T + m[:3, 3]


def clip_points(m, points):
    """Points (..., 3) through a view-projection m: their homogeneous clip coordinates (..., 4)."""
    p = np.asarray(points, float)
    return np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1) @ np.asarray(m, float).T


def gl_bytes(m):
    """Bytes of a matrix in the column-major order GLSL expects."""
    return np.asarray(m, dtype="f4").T.tobytes()


def box_corners(lo, hi):
    """The 8 corners of axis-aligned boxes: (8, 3) for one box, (..., 8, 3) for arrays of them."""
    lo, hi = np.asarray(lo), np.asarray(hi)
    return np.stack([np.where([(k >> axis) & 1 for axis in range(3)], hi, lo) for k in range(8)], axis=-2)


def outside_frustum(corners, view_projection):
    """Whether boxes given by their corners (..., 8, 3) lie outside a view's frustum: all of a
    box's corners beyond one clip plane (-w <= x, y, z <= w). The conditions are linear in the
    homogeneous point, so the whole box is then beyond it; a box across the frustum's edges
    counts as inside."""
    clip = clip_points(view_projection, corners)
    w = clip[..., 3:]
    return np.any(np.all(clip[..., :3] > w, axis=-2) | np.all(clip[..., :3] < -w, axis=-2), axis=-1)


def euler_deg_from_rotation(r):
    """Angles [x, y, z] in degrees with rotate_euler_deg(angles)[:3, :3] == r, for a 3x3 rotation
    matrix r (R = Rz Ry Rx; y in [-90, 90]; at y = +-90 degrees the x angle is taken as 0)."""
    r = np.asarray(r, float)
    y = math.asin(float(np.clip(-r[2, 0], -1.0, 1.0)))
    if abs(r[2, 0]) < 1.0 - 1e-12:
        x = math.atan2(r[2, 1], r[2, 2])
        z = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: Rz Ry(+-90) alone
        x = 0.0
        z = math.atan2(-r[0, 1], r[1, 1])
    return np.degrees([x, y, z]) + 0.0  # no -0.0


def quaternion_rotation(q):
    """3x3 rotation matrix of a quaternion [x, y, z, w] (glTF's order), normalized first (the
    conversion of euclideanspace.com's quaternionToMatrix, as pyrr's create_from_quaternion)."""
    q = np.asarray(q, float)
    x, y, z, w = (float(c) for c in q / np.linalg.norm(q))
    xx, yy, zz, ww = x * x, y * y, z * z, w * w
    inverse = 1.0 / (xx + yy + zz + ww)
    return np.array([
        [(xx - yy - zz + ww) * inverse, 2.0 * (x * y - z * w) * inverse, 2.0 * (x * z + y * w) * inverse],
        [2.0 * (x * y + z * w) * inverse, (-xx + yy - zz + ww) * inverse, 2.0 * (y * z - x * w) * inverse],
        [2.0 * (x * z - y * w) * inverse, 2.0 * (y * z + x * w) * inverse, (-xx - yy + zz + ww) * inverse]])


def decompose(m, tolerance=1e-6):
    """(translation, rotation_deg, scale) with compose(...) == m for a 4x4 matrix T * R * S, or
    None where m is not one (shear, projection, zero scale). A mirroring matrix gets a
    negative x scale."""
    m = np.asarray(m, float)
    linear = m[:3, :3]
    scale_xyz = np.linalg.norm(linear, axis=0)
    if np.any(scale_xyz == 0) or not np.allclose(m[3], [0, 0, 0, 1], atol=tolerance):
        return None
    if np.linalg.det(linear) < 0:
        scale_xyz[0] = -scale_xyz[0]
    rotation = linear / scale_xyz
    if not np.allclose(rotation.T @ rotation, np.eye(3), atol=tolerance):
        return None
    return m[:3, 3].copy(), euler_deg_from_rotation(rotation), scale_xyz
