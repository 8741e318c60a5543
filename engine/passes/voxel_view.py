"""Voxel views: the grid ray-marched from the camera at one mip level, as blocks."""
import numpy as np

from .. import transforms
from ..constants import TEXTURE_UNIT
from .target import ScreenTarget

SHOW = {"voxels": 0, "voxel-normals": 1, "voxel-albedo": 2}


class VoxelViewPass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="fullscreen.vert", fragment_shader="voxel_view.frag")
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def render(self, mode, volume, mip, voxel_uniforms, view_projection, camera_position):
        volume.use(TEXTURE_UNIT["VOXEL_INSPECT"])
        self.program.set(**voxel_uniforms, show=SHOW[mode], mip=float(mip),
                         inverse_view_projection=transforms.gl_bytes(np.linalg.inv(view_projection)),
                         camera_position=tuple(camera_position), viewport_size=tuple(float(x) for x in self.target.size))
        self.target.draw(self.program)

    def release(self):
        self.target.release()
        self.program.release()
