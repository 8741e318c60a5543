"""The face views cones read: composed per covered voxel from its base radiance and the light
it gathered, L = L_base + rho G (rho: its reflectance), times the coverage of each face
direction; then their mip levels, built over the covered cells of each level only."""
import numpy as np

from ..constants import STORAGE_BINDING, TEXTURE_UNIT, VOXEL_FACES


class FaceViewsPass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.compose_program = programs.compute("voxel_compose.comp")
        self.mipmap_program = programs.compute("voxel_mipmap.comp")
        self.totals_program = programs.compute("voxel_totals.comp")
        self.totals_buffer = ctx.buffer(reserve=16 * VOXEL_FACES)

    def compose(self, grid, gathered=None):
        """Level 0 of the face views from the base radiance plus rho times `gathered` (a
        volume of the grid, or None before the first bounce)."""
        grid.use_surface()
        grid.base.use(TEXTURE_UNIT["VOXEL_BASE"])
        if gathered is not None:
            gathered.use(TEXTURE_UNIT["VOXEL_GATHERED"])
        grid.covered.bind("COVERED")
        grid.bind_faces()
        self.compose_program.set(**grid.uniforms(), include_gathered=gathered is not None)
        grid.dispatch(self.compose_program, grid.covered.count)

    def mipmap(self, grid):
        """Every coarser level of the face views, level after level, over its covered cells."""
        grid.use_faces()
        grid.cells.bind_to_storage_buffer(STORAGE_BINDING["CELLS"])
        uniforms = grid.uniforms()
        for level in range(1, grid.mip_count):
            grid.bind_faces(level)
            self.mipmap_program.set(**uniforms, level=level, first=grid.level_first[level])
            grid.dispatch(self.mipmap_program, grid.level_counts[level])

    def totals(self, grid):
        """Mean premultiplied radiance (rgb) of the face views over the grid, summed over the
        six faces (from the 1^3 levels)."""
        grid.use_faces()
        self.totals_buffer.bind_to_storage_buffer(STORAGE_BINDING["READBACK"])
        self.totals_program.set(top_level=grid.mip_count - 1)
        self.totals_program.program.run(1)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)
        return np.frombuffer(self.totals_buffer.read(), dtype="f4").reshape(VOXEL_FACES, 4)[:, :3].sum(axis=0).astype(np.float64)

    def release(self):
        for resource in (self.compose_program, self.mipmap_program, self.totals_program, self.totals_buffer):
            resource.release()
