"""The voxels read back, for the voxel views, Renderer.voxels and tests: an array of values per
record as a dense volume of the stacked levels (with its hardware mip chain), and a mip level
of any volume as numpy. A read back waits for the GPU: inspection only, never in a frame the
viewer renders for its image."""
import math
from dataclasses import dataclass

import moderngl
import numpy as np

from ..core.constants import NO_VOXEL, VOLUME_GROUP
from .grid import TEXEL_BYTES, build_mips, gpu_bytes, unpack_voxels, volume_image, zero_volume


@dataclass(frozen=True)
class VoxelLists:
    """The voxel lists and records of the last frame read back (Renderer.voxel_lists): voxel
    coordinates (k, 3) as x, y, z of the levels' stack (level L at z in [L n, (L + 1) n))."""
    covered: np.ndarray  # the voxels some surface covers
    records: np.ndarray  # the record each of them holds: its place in the covered list
    touched: np.ndarray  # the voxels the last voxelization touched
    index: np.ndarray  # per voxel of the stack, flat (x + n (y + n z)), its record + 1 (0: none)
    free: np.ndarray  # the records the pool holds free
    short: int  # records the last voxelizations asked the pool for in vain
    anchors: np.ndarray  # per covered voxel, its gather anchor word (lib/gather_anchors.glsl), or None


def read_lists(grid, anchors):
    """VoxelLists of `grid`, with the anchor word of each record from `anchors` (GatherPass;
    None where the frame found none)."""
    entries = grid.covered.read_entries()
    records = np.flatnonzero(entries != NO_VOXEL)  # a free record's entry is NO_VOXEL
    pool = grid.records.read_pool()  # free count, short, the free records
    return VoxelLists(covered=unpack_voxels(entries[records]), records=records,
                      touched=unpack_voxels(grid.touched.read_entries()), index=grid.records.read_index(),
                      free=pool[2:2 + pool[0]].copy(), short=int(pool[1]),
                      anchors=None if anchors is None else anchors[records])


class VoxelInspection:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.read_program = programs.compute("voxel_grid/read_level.comp", reads=("TEX_VOXEL_INSPECT",),
                                             writes=("SSBO_READBACK",))
        self.scatter_program = programs.compute("voxel_grid/scatter_values.comp", reads=("SSBO_COVERED", "SSBO_VOXEL_RECORD",
                                                "SSBO_INSPECT_VALUES"), writes=("IMG_INSPECT_OUT",))
        self.volume = None  # the dense volume, of one grid size: (n, levels) in `self.size_of`
        self.size_of = None

    def dense(self, grid, values, mips=True):
        """An array of values of `grid` as a volume of its stacked levels, n x n x L n (zero
        where no surface covers a voxel), with its hardware mip chain built where `mips`: one
        volume, made again at each call."""
        n = grid.n
        if self.size_of != (n, grid.levels):
            self._release_volume()
            self.volume = zero_volume(self.ctx, n, grid.levels)
            self.size_of = (n, grid.levels)
        volume = self.volume
        volume.write(bytes(TEXEL_BYTES * grid.voxel_count))
        self.scatter_program.set(**grid.uniforms())
        grid.dispatch(self.scatter_program, grid.covered.segment(), SSBO_COVERED=grid.covered.buffer,
                      SSBO_VOXEL_RECORD=grid.records.index, SSBO_INSPECT_VALUES=values,
                      IMG_INSPECT_OUT=volume_image(volume))
        if mips:
            return build_mips(volume)
        volume.filter = (self.ctx.LINEAR, self.ctx.LINEAR)
        return volume

    def read_level(self, grid, volume, level=0):
        """One mip level of a volume of `grid` (or of an array of its values, made `dense`) as
        float32 (depth, n, n, 4), indexed [z, y, x] (the levels one after the other along z,
        and the face views' depth holds their six stacks of levels one after the other)."""
        if isinstance(volume, moderngl.Buffer):
            volume = self.dense(grid, volume, mips=level > 0)
        width, height, depth = (max(1, side >> level) for side in volume.size)
        shape = (depth, height, width, 4)
        if level == 0:
            return np.frombuffer(volume.read(), dtype="f2").reshape(shape).astype("f4")
        buffer = self.ctx.buffer(reserve=width * height * depth * 16)
        try:
            self.read_program.set(level=level)
            self.read_program.run(*(math.ceil(side / VOLUME_GROUP) for side in (width, height, depth)),
                                  TEX_VOXEL_INSPECT=volume, SSBO_READBACK=buffer)
            self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)
            return np.frombuffer(buffer.read(), dtype="f4").reshape(shape).copy()
        finally:
            buffer.release()

    def read_faces(self, grid, faces, level):
        """Mip level `level` (1 up) of the face views `faces` (FaceViewsPass.volume), as
        read_level reads a volume."""
        return self.read_level(grid, faces, level - 1)

    def memory_bytes(self, grid):
        """GPU bytes of the dense volume, where it is of `grid`'s size (with its mip chain)."""
        if self.volume is None or self.size_of != (grid.n, grid.levels):
            return 0
        return gpu_bytes(self.volume, mipmapped=True)

    def _release_volume(self):
        if self.volume is not None:
            self.volume.release()
        self.volume = self.size_of = None

    def release(self):
        self._release_volume()
        self.read_program.release()
        self.scatter_program.release()
