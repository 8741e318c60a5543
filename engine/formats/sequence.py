"""Sequences of frames (`vct render --frames N`): the time and camera of each frame, the file
names a pattern gives them, and the video they make. GL-free: the CLI renders each frame with
one Renderer, which runs only what changed since the frame before."""
import contextlib
import dataclasses
import os
import re
import secrets
from pathlib import Path

import numpy as np

from ..core.errors import VctError
from ..core.transforms import rotate_euler_deg

MAX_FRAMES = 100000
VIDEO_SUFFIXES = (".mp4",)
_FRAME_NUMBER = re.compile(r"%0?\d*d")  # printf's %d, %4d, %04d


def frame_times(frames, fps, start):
    """The time in seconds of each frame: frame i at start + i / fps."""
    return [start + i / fps for i in range(frames)]


def check_pattern(pattern, flag, frames):
    """An output name for `frames` frames: one %d (e.g. f_%04d.png) where there is more than
    one frame, which the frame's number fills; a name without one is a single frame's."""
    numbers = _FRAME_NUMBER.findall(pattern)
    others = pattern.replace("%%", "").count("%") - len(numbers)
    if len(numbers) > 1 or others:
        raise VctError("must hold one %d (or %04d) and no other %", source=pattern, field=flag)
    if frames > 1 and not numbers:
        raise VctError(f"{frames} frames need a %d in the name, which the frame's number fills (e.g. f_%04d.png)",
                       source=pattern, field=flag)


def frame_path(pattern, index):
    """The name of frame `index` of `pattern` (check_pattern's form)."""
    return pattern % index if _FRAME_NUMBER.search(pattern) else pattern.replace("%%", "%")


def orbit(camera, fraction):
    """The camera turned by 2 pi `fraction` about the vertical (+y) axis through its look-at
    point: a turntable."""
    turn = rotate_euler_deg([0.0, 360.0 * fraction, 0.0])[:3, :3]
    return dataclasses.replace(camera, position=camera.look_at + turn @ (camera.position - camera.look_at),
                               up=turn @ camera.up)


class VideoFile:
    """An H.264 video (yuv420p, as players expect; an odd width or height padded by a pixel)
    written through the ffmpeg binary of imageio-ffmpeg to a temporary file beside `path`,
    moved over it by `finish()` once every frame is in; `discard()` removes it."""

    def __init__(self, path, size, fps):
        import imageio_ffmpeg

        self.path = Path(path)
        self.temporary = self.path.parent / f".vct-{secrets.token_hex(8)}.tmp"
        self.writer = imageio_ffmpeg.write_frames(
            str(self.temporary), size, fps=fps, codec="libx264", pix_fmt_out="yuv420p", macro_block_size=1,
            output_params=["-f", "mp4", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"], ffmpeg_log_level="error")
        self.writer.send(None)  # starts ffmpeg

    def append(self, pixels):
        """Add a frame: uint8 (H, W, 3), row 0 at the top."""
        self.writer.send(np.ascontiguousarray(pixels))

    def finish(self):
        try:
            self.writer.close()
            os.replace(self.temporary, self.path)
        except (OSError, RuntimeError) as exc:
            self.discard()
            raise VctError(f"cannot write the video ({exc})", source=self.path, field="--video") from None

    def discard(self):
        with contextlib.suppress(Exception):
            self.writer.close()
        with contextlib.suppress(OSError):
            self.temporary.unlink(missing_ok=True)


@contextlib.contextmanager
def video_file(path, size, fps):
    """A VideoFile that is finished when the block completes and discarded when it does not."""
    video = VideoFile(path, size, fps)
    try:
        yield video
    except BaseException:
        video.discard()
        raise
    video.finish()


def describe_times(times):
    """"t = 1.5 s" or "t = 0..1.97 s" for a report."""
    if len(times) == 1:
        return f"t = {times[0]:g} s"
    return f"t = {times[0]:g}..{times[-1]:.4g} s"

