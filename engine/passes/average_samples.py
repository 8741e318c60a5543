"""Anti-aliasing by supersampling: the mean of a frame's images drawn with the camera jittered
over each pixel (engine/core/sampling.py pixel_offsets), a box pixel filter as the path-traced
references have. It owns the mean; the voxels and their light are the same for every sample."""
import math

from ..core.constants import GL_IMAGE_FORMAT, SCREEN_GROUP
from ..gpu.bindings import Image
from .target import ScreenTarget


class AverageSamplesPass:
    def __init__(self, ctx, programs, size):
        self.ctx = ctx
        self.program = programs.compute("average_samples/add_sample.comp", reads=("TEX_HDR_INPUT",),
                                        writes=("IMG_AVERAGE_OUT",))
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def add(self, image, count):
        """Add `image` (a ScreenTarget), the frame's sample number `count` (1 for the first),
        to the mean of the samples before it; returns the target holding the mean."""
        self.program.set(sample_weight=1.0 / count)
        width, height = self.target.size
        self.program.run(math.ceil(width / SCREEN_GROUP), math.ceil(height / SCREEN_GROUP),
                         TEX_HDR_INPUT=image.texture,
                         IMG_AVERAGE_OUT=Image(self.target.texture, read=True, write=True, format=GL_IMAGE_FORMAT["rgba32f"]))
        # The mean as the next sample loads it and its readers fetch or read it back.
        self.ctx.memory_barrier(self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.TEXTURE_FETCH_BARRIER_BIT
                                | self.ctx.TEXTURE_UPDATE_BARRIER_BIT)
        return self.target

    def release(self):
        self.target.release()
        self.program.release()
