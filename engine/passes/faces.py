"""The face views cones read: composed per covered voxel from its base radiance and the light
it gathered, L = L_base + rho G (rho: its reflectance), which cones see times the coverage of
each face direction (level 0); then their mip levels, built over the covered cells of each
level only, and zeroed where a voxelization empties cells (cells no surface covers read zero:
the mipmap writes only faces with coverage)."""
import numpy as np

from ..core.constants import VOXEL_FACES
from ..voxels.grid import VoxelGrid, build_mips, gpu_bytes, volume_image, zero_volume
from ..voxels.records import RecordArrays


class FaceViewsPass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.compose_program = programs.compute(
            "faces/compose_face_views.comp", writes=("SSBO_VOXEL_REFLECTED",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS, "SSBO_VOXEL_BASE", "SSBO_VOXEL_GATHERED"))
        self.mipmap_program = programs.compute("faces/mipmap_face_views.comp", reads=("SSBO_CELLS", "SSBO_SEGMENTS", *VoxelGrid.CONE_READS),
                                               writes=("IMG_FACES_OUT",))
        self.totals_program = programs.compute("faces/sum_face_views.comp", reads=("TEX_VOXEL_FACES",), writes=("SSBO_READBACK",))
        self.clear_program = programs.compute("voxel_grid/clear_cells.comp", reads=("SSBO_CELLS", "SSBO_SEGMENTS"),
                                              writes=("IMG_FACES_OUT",))
        self.totals_buffer = ctx.buffer(reserve=16 * VOXEL_FACES)
        self.values = RecordArrays(1)  # the light each voxel reflects, per record
        self.volume = None  # the face views from mip level 1 up, for the records store in self.values

    def hold(self, grid):
        """Hold the reflected light for the grid's records and the face views for its levels
        (zero when made); True when made now."""
        if not self.values.hold(grid.records):
            return False
        if self.volume is not None:
            self.volume.release()
        self.volume = build_mips(zero_volume(self.ctx, grid.n // 2, VOXEL_FACES * grid.levels))  # from mip level 1
        return True

    def faces_out(self, level):
        """Mip level `level` (1 up) of the face views, to write (as IMG_FACES_OUT)."""
        return volume_image(self.volume, level - 1)

    @property
    def reflected(self):
        """The light each voxel reflects per record (rgb; a = 1): level 0 of the face views."""
        return self.values.arrays[0]

    def cones(self, grid):
        """What a program tracing cones binds (VoxelGrid.CONE_READS): the voxels' surface and the
        light they reflect (level 0), and the face views (level 1 up)."""
        return dict(zip(VoxelGrid.CONE_READS, (*grid.surface().values(), self.reflected, self.volume)))

    def compose(self, grid, base, gathered, segment, levels=None):
        """Level 0 of the face views, the light the voxels reflect, from the base radiance
        `base` plus rho times `gathered` (arrays per record; gathered None before the first
        bounce), for the voxels of `segment` (a VoxelSegment) that lie in `levels` (None: every
        level). Returns the reflected light."""
        self.hold(grid)
        self.compose_program.set(**grid.uniforms(), include_gathered=gathered is not None, composed_levels=grid.level_mask(levels))
        grid.dispatch(self.compose_program, segment, SSBO_VOXEL_LIST=segment.buffer, **grid.surface(), SSBO_VOXEL_BASE=base,
                      SSBO_VOXEL_GATHERED=gathered, SSBO_VOXEL_REFLECTED=self.reflected)
        return self.reflected

    def mipmap(self, grid, level_one=None, levels=None):
        """Every coarser level of the face views, level after level: level 1 over the cells
        that hold the entries of `level_one`, (VoxelSegment, level of its entries) pairs (the
        cells of the voxels composed: an interleave class's, or those of the voxels a
        voxelization touched, which it zeroed; None: every covered cell), the coarser levels
        over every covered cell; of the grid levels `levels` only (None: every level).
        Returns the face views."""
        uniforms = grid.uniforms()
        level_one = level_one or [(grid.cells.segment(1), 1)]
        for level in range(1, grid.mip_count):
            for segment, entry_level in level_one if level == 1 else [(grid.cells.segment(level), level)]:
                self.mipmap_program.set(**uniforms, voxel_entries=entry_level == 0, mipmapped_levels=grid.level_mask(levels))
                grid.dispatch(self.mipmap_program, segment, SSBO_CELLS=segment.buffer, **self.cones(grid),
                              IMG_FACES_OUT=self.faces_out(level))
        return self.volume

    def clear_level(self, grid, level):
        """Before a scroll of grid level `level` moves its voxels: its face views zeroed over the
        cells it holds, at every mip level."""
        self._clear(grid, [(grid.cells.segment(mip), False) for mip in range(1, grid.mip_count)], [level])

    def clear_covered(self, grid):
        """Before a full voxelization: the face views zeroed over every covered cell."""
        self._clear(grid, [(grid.cells.segment(mip), False) for mip in range(1, grid.mip_count)])

    def clear_touched(self, grid):
        """After a voxelization of some voxels: the face views zeroed over the cells of the
        voxels it touched, at every mip level, until the mipmap builds them again."""
        self._clear(grid, [(grid.touched.segment(), True)] * (grid.mip_count - 1))

    def _clear(self, grid, segments, levels=None):
        """Zero mip level k + 1 of the face views (grid levels `levels`; None: every level)
        over the cells of the k-th (VoxelSegment, whether its entries are voxels) pair."""
        for mip, (segment, voxel_entries) in enumerate(segments, start=1):
            self.clear_program.set(**grid.uniforms(), voxel_entries=voxel_entries, views=VOXEL_FACES,
                                   cleared_levels=grid.level_mask(levels))
            grid.dispatch(self.clear_program, segment, SSBO_CELLS=segment.buffer, IMG_FACES_OUT=self.faces_out(mip))

    def request_totals(self, grid):
        """Compute the mean premultiplied radiance (rgb) of the face views over the grid,
        summed over the six faces (from the 1^3 levels), into a buffer read_totals reads."""
        self.totals_program.set(top_level=grid.mip_count - 2)  # the face views hold levels 1 and up
        self.totals_program.run(1, TEX_VOXEL_FACES=self.volume, SSBO_READBACK=self.totals_buffer)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)

    def read_totals(self):
        """The totals the last request_totals computed (read back from the GPU)."""
        return np.frombuffer(self.totals_buffer.read(), dtype="f4").reshape(VOXEL_FACES, 4)[:, :3].sum(axis=0).astype(np.float64)

    def totals(self, grid):
        """The face views' totals, computed and read back now."""
        self.request_totals(grid)
        return self.read_totals()

    def memory_bytes(self):
        """The reflected light's array and the face views with their mip chain."""
        volume = gpu_bytes(self.volume, mipmapped=True) if self.volume is not None else 0
        return self.values.memory_bytes() + volume

    def release(self):
        self.values.release()
        if self.volume is not None:
            self.volume.release()
            self.volume = None
        for resource in (self.compose_program, self.mipmap_program, self.totals_program, self.clear_program, self.totals_buffer):
            resource.release()
