"""Reading a Renderer's results back: the last frame's radiance, its display pixels, the world
points its pixels see, the voxel volumes and lists, and what the GPU holds. A part of the
Renderer (a base class of it), which reads the targets and voxels its passes wrote and writes
nothing; `current` makes the renderer's context current around its public methods."""
import functools
import numbers

import numpy as np

from ..core.errors import VctError
from ..formats.output import save_png
from ..gpu.bindings import forget_bindings
from ..passes.voxel_view import shown_values
from ..voxels.inspection import read_lists

VOXEL_VOLUMES = {"radiance": "voxels", "normal": "voxel-normals", "albedo": "voxel-albedo", "gathered": None}


def current(method):
    """Make the renderer's context current around a public method: several renderers (and
    their contexts) may live in one process. After close() the method raises VctError."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        if self.ctx is None:
            raise VctError("the renderer is closed (close() was called)", field=f"Renderer.{method.__name__}")
        if self._context_entered:  # nested call: already current
            return method(self, *args, **kwargs)
        self._context_entered = True
        try:
            with self.ctx:
                return method(self, *args, **kwargs)
        finally:
            self._context_entered = False
    return wrapper


class Readback:
    """The Renderer's read-back methods (a base class of it)."""

    @current
    def voxels(self, name="radiance", level=0):
        """A voxel volume of the last frame as float32 (L n, n, n, 4), indexed [z, y, x] (the
        grid's L levels one after the other along z):
        "radiance" (emission + direct light, a = opacity), "normal" (mean normal, its length
        the coherence; a: the surfaces' opacity, the share of the voxel's face they cover times
        their alpha, at most 1), "albedo",
        "gathered" (the diffuse light each voxel gathered in the latest bounce,
        G = sum_j w_j L(p, w_j)); levels above 0 (up to log2 n, one voxel) come from hardware
        mipmaps."""
        if name not in VOXEL_VOLUMES:
            raise VctError(f"must be one of {', '.join(VOXEL_VOLUMES)}, got {name!r}", field="name")
        if not self.grid.n:
            raise VctError("no voxels yet: render a frame in a mode that uses them first", field="voxels")
        top = self.grid.n.bit_length() - 1
        if not isinstance(level, numbers.Integral) or isinstance(level, bool) or not 0 <= level <= top:
            raise VctError(f"must be a whole number in 0..{top} for grid {self.grid.n}, got {level!r}", field="level")
        values = self._gathered() if name == "gathered" else shown_values(self.grid, self.inject.base, VOXEL_VOLUMES[name])
        return self.inspection.read_level(self.grid, values, level)

    def voxel_memory_bytes(self):
        """GPU bytes of the voxel grid and of the passes' storage sized by it."""
        owners = (self.voxelize, self.gather, self.inject, self.faces, self.emitter_light, self.sky_light)
        return self.grid.memory_bytes() + sum(owner.memory_bytes() for owner in owners) + self.inspection.memory_bytes(self.grid)

    @current
    def radiance(self):
        """The last frame's linear radiance (or encoded data view), float32 (H, W, 3), row 0 at the top."""
        return self.output.read()[..., :3].copy()

    @current
    def positions(self):
        """The world point each pixel of the last frame sees, float32 (H, W, 3), row 0 at the
        top; NaN where it sees no surface."""
        width, height = self.size
        texels = np.frombuffer(self.gbuffer.target.textures[0].read(), "f4").reshape(height, width, 4)[::-1]
        return np.where(texels[..., 3:] > 0.0, texels[..., :3], np.nan).astype("f4")

    @property
    def voxel_layout(self):
        """Where the voxels of the last frame lie: a VoxelLayout (n, regions, levels, voxel
        sizes, bounds, and the room of the voxel lists)."""
        return self.grid.layout()

    @property
    def draw_calls(self):
        """The multi-draws the last frame issued."""
        return self.scene_buffers.draw_calls

    @property
    def held_meshes(self):
        """The meshes the GPU holds (one copy of each, whatever the nodes sharing it), and
        their vertices: (meshes, vertices)."""
        pool = self.scene_buffers.pool
        return len(pool.entries), pool.vertex_count

    def texture_memory_bytes(self):
        """GPU bytes of the scene's textures."""
        return self.scene_buffers.textures.memory_bytes()

    @current
    def voxel_lists(self):
        """The voxel lists of the last frame read back: VoxelLists (the covered voxels, the
        touched ones, their records and gather anchors). A read back waits for the GPU."""
        found = self.gather.anchors_epoch is self.grid.epoch
        return read_lists(self.grid, self.gather.read_anchors() if found else None)

    @current
    def display_target(self):
        """Tone-map the last frame on the GPU; returns the 8-bit ScreenTarget (for a window)."""
        s = self.frame_settings
        if not self._owns_context:
            forget_bindings(self.ctx)
        with self.timed("tonemap"):
            if s.shown.data:  # encoded data: shown as stored, no curve, no sRGB
                return self.tonemap.render(self.output.texture, 1.0, "none", encode_srgb=False)
            return self.tonemap.render(self.output.texture, s.exposure, s.tonemap)

    @current
    def tonemapped(self):
        """The last frame as display pixels, uint8 (H, W, 3), row 0 at the top."""
        return self.display_target().read()[..., :3].copy()

    def save_png(self, path):
        """Tone-map the last frame and write it as PNG (written to a temporary name, then moved)."""
        save_png(path, self.tonemapped())
