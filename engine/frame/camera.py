"""The camera a frame is seen from: its matrices for the image (FrameCamera, from the scene's
Camera by `frame_camera`) and the uniform block the passes read it from (glsl/lib/camera.glsl),
written when it changed (CameraBlock)."""
import dataclasses
import math

import numpy as np

from ..core import transforms
from ..core.constants import struct_dtype
from ..gpu.functions import write_buffer

NEAR_PLANE = 0.01
CAMERA_DTYPE = struct_dtype("FrameCamera")


@dataclasses.dataclass(frozen=True)
class FrameCamera:
    """The camera's position, unit forward direction and view-projection for the frame's image,
    its far plane's distance, and the uniform buffer it is written into (CameraBlock.write)."""

    position: np.ndarray
    forward: np.ndarray
    view_projection: np.ndarray
    far: float
    centred_view_projection: np.ndarray  # the view-projection through the pixels' centres (no pixel offset)
    pixel_angle: float  # radians between neighbouring pixels' rays, at the image centre (0: orthographic)
    orthographic: bool = False
    buffer: object = None  # the uniform buffer the frame's camera is written into (CameraBlock)

    def record(self):
        """The camera as glsl/lib/camera.glsl reads it (GLSL_STRUCTS["FrameCamera"])."""
        record = np.zeros(1, CAMERA_DTYPE)
        record["view_projection"] = np.asarray(self.view_projection, "f4").T.ravel()
        record["inverse_view_projection"] = np.asarray(np.linalg.inv(self.view_projection), "f4").T.ravel()
        record["position"] = (*self.position, float(self.orthographic))
        record["forward"][0, :3] = self.forward
        return record

    def resources(self):
        """The camera's uniform block, as a program that reads glsl/lib/camera.glsl binds it."""
        return {"UBO_CAMERA": self.buffer.buffer}


class CameraBlock:
    """The uniform buffer holding the frame's camera: written when the camera changed."""

    def __init__(self, ctx):
        self.buffer = ctx.buffer(reserve=CAMERA_DTYPE.itemsize)
        self.held = None

    def write(self, camera):
        """Hold `camera` (a FrameCamera); returns it as one that binds this buffer."""
        data = camera.record().tobytes()
        if data != self.held:
            write_buffer(self.buffer, data)
            self.held = data
        return dataclasses.replace(camera, buffer=self)

    def release(self):
        self.buffer.release()


def frame_camera(camera, size, bounds, pixel_offset=(0.0, 0.0)):
    """The camera's matrices for an image of `size`, its pixels' centres moved by `pixel_offset`
    (x right, y up, in pixels: a jittered sample); the far plane lies past the farthest corner
    of the scene's bounds."""
    corners = transforms.box_corners(*bounds)
    far = float(np.max(np.linalg.norm(corners - camera.position, axis=1))) * 1.1 + 1.0
    forward = camera.look_at - camera.position
    projection = camera.projection_matrix(size[0] / size[1], NEAR_PLANE, far)
    # Clip space shifted by the offset in normalized device coordinates: x' = x + 2 dx / W w.
    shift = np.eye(4)
    shift[:2, 3] = 2.0 * np.asarray(pixel_offset, float) / np.asarray(size, float)
    view_projection = projection @ camera.view_matrix()
    orthographic = camera.projection == "orthographic"
    pixel_angle = 0.0 if orthographic else 2.0 * math.tan(math.radians(camera.vertical_fov_deg) / 2.0) / size[1]
    return FrameCamera(np.asarray(camera.position, float), forward / np.linalg.norm(forward),
                       shift @ view_projection, far, view_projection, pixel_angle, orthographic)
