"""Temporal anti-aliasing for the frames a viewer shows one after the other: each frame is seen
through a point of the pixel that moves along the Halton sequence (`pixel_offset`), and
blended into the history of the frames before, reprojected through the camera's and each
point's own motion (the G-buffer's), clamped to the frame's neighbourhood and dropped where
disoccluded (glsl/temporal/resolve_history.comp). A still view converges to the mean of TEMPORAL_FRAMES
jittered samples, the headless renders' box filter, and then rests: while nothing changes, the
frame shows the history as it stands (`converged`, `held`). It owns the history (two images and
the distance each pixel saw, written in turn) and the last frame's view."""
import math

import numpy as np

from ..core.constants import GL_IMAGE_FORMAT, SCREEN_GROUP, TEMPORAL_FRAMES
from ..core.sampling import pixel_offsets
from ..gpu.bindings import Image
from .target import ScreenTarget

OFFSETS = pixel_offsets(TEMPORAL_FRAMES)


def sky_reprojection(camera, previous_view_projection):
    """The matrix taking a point of this frame's far plane (centred NDC, z = 1, w = 1) to the
    last frame's clip space as a direction from the eye (a point of the sky, infinitely far):
    previous_view_projection @ [I | -eye; 0] @ inverse(centred_view_projection), its sign
    making w > 0 where the sky lies ahead."""
    unproject = np.linalg.inv(np.asarray(camera.centred_view_projection, np.float64))
    to_direction = np.zeros((4, 4))
    to_direction[:3, :3] = np.eye(3)
    to_direction[:3, 3] = -np.asarray(camera.position, np.float64)
    sign = 1.0 if (unproject @ (0.0, 0.0, 1.0, 1.0))[3] > 0 else -1.0
    return sign * (np.asarray(previous_view_projection, np.float64) @ to_direction @ unproject)


class TemporalPass:
    def __init__(self, ctx, programs, size):
        self.ctx = ctx
        self.program = programs.compute(
            "temporal/resolve_history.comp",
            reads=("TEX_HDR_INPUT", "TEX_GBUF_POSITION", "TEX_GBUF_PREVIOUS", "TEX_HISTORY", "TEX_HISTORY_DISTANCE", "UBO_CAMERA"),
            writes=("IMG_HISTORY_OUT", "IMG_HISTORY_DISTANCE_OUT"))
        self.histories = self.distances = ()
        self.frame = 0          # frames resolved: the next one's offset is OFFSETS[frame % TEMPORAL_FRAMES]
        self.previous = None    # (centred view-projection, eye, settings) of the last frame resolved
        self.still = 0          # frames resolved in a row from that view, with those settings, nothing moving
        self.last_offset = OFFSETS[0]  # the point of the pixel the last frame resolved was seen through
        self.resize(size)

    def resize(self, size):
        self._release_targets()
        self.histories = [ScreenTarget(self.ctx, size) for _ in range(2)]
        self.distances = [ScreenTarget(self.ctx, size, components=1) for _ in range(2)]
        for target in self.histories:  # read between pixels where the view moved
            target.texture.filter = (self.ctx.LINEAR, self.ctx.LINEAR)
        for target in (*self.histories, *self.distances):  # the edge pixels, not the far side's, at the image's edges
            target.texture.repeat_x = target.texture.repeat_y = False
        self.size = size
        self.forget()

    def converged(self, settings):
        """Whether the history holds TEMPORAL_FRAMES samples of a still view with `settings`:
        a frame that changes nothing may show it as it stands (held)."""
        return self.still >= TEMPORAL_FRAMES and self.previous[2] == settings

    def pixel_offset(self):
        """Where in its pixels the next frame is seen from: (x, y) in -0.5..0.5; once converged,
        the last frame's point (a frame that changes nothing then reads as the last one)."""
        return self.last_offset if self.still >= TEMPORAL_FRAMES else OFFSETS[self.frame % TEMPORAL_FRAMES]

    def held(self):
        """The history as the last frame left it."""
        return self.histories[self.frame % 2]

    def resolve(self, image, gbuffer, buffers, camera, settings, pixel_offset):
        """Blend `image` (a ScreenTarget seen through `pixel_offset` with `settings`; its
        G-buffer `gbuffer`, drawn with the motion; `buffers`, SceneBuffers, say whether a draw
        moved) into the history; returns the target holding the result, the frame to show. A
        frame resolved once converged changed something: the samples start again."""
        read, write = self.frame % 2, (self.frame + 1) % 2
        valid = self.previous is not None
        view_projection, eye, _ = self.previous if valid else (camera.centred_view_projection, camera.position, None)
        still = valid and np.array_equal(view_projection, camera.centred_view_projection) \
            and self.previous[2] == settings and not len(buffers.moving) and self.still < TEMPORAL_FRAMES
        self.still = self.still + 1 if still else 0
        self.last_offset = pixel_offset
        self.program.set(centred_view_projection=np.asarray(camera.centred_view_projection, "f4").T.ravel(),
                         previous_view_projection=np.asarray(view_projection, "f4").T.ravel(),
                         sky_reprojection=np.asarray(sky_reprojection(camera, view_projection), "f4").T.ravel(),
                         previous_eye=tuple(float(x) for x in eye), history_valid=valid)
        width, height = self.size
        self.program.run(math.ceil(width / SCREEN_GROUP), math.ceil(height / SCREEN_GROUP),
                         TEX_HDR_INPUT=image.texture, **gbuffer.resources("GBUF_POSITION", "GBUF_PREVIOUS"),
                         TEX_HISTORY=self.histories[read].texture, TEX_HISTORY_DISTANCE=self.distances[read].texture,
                         **camera.resources(),
                         IMG_HISTORY_OUT=Image(self.histories[write].texture, format=GL_IMAGE_FORMAT["rgba32f"]),
                         IMG_HISTORY_DISTANCE_OUT=Image(self.distances[write].texture, format=GL_IMAGE_FORMAT["r32f"]))
        # The history as its readers fetch or read it back: the display, the next frame.
        self.ctx.memory_barrier(self.ctx.TEXTURE_FETCH_BARRIER_BIT | self.ctx.TEXTURE_UPDATE_BARRIER_BIT)
        self.previous = (camera.centred_view_projection, camera.position, settings)
        self.frame += 1
        return self.histories[write]

    def forget(self):
        """Start the history anew with the next frame."""
        self.previous = None
        self.still = 0

    def _release_targets(self):
        for resource in (*self.histories, *self.distances):
            resource.release()

    def release(self):
        self._release_targets()
        self.program.release()
