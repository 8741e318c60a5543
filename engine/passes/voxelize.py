"""Voxelization pass: the scene's surfaces into the N^3 grid (geometry-shader dominant-axis
projection, conservative dilation, fixed-point sums with atomics), resolved into the grid's
surface volumes: albedo, mean normal, emission and surface offset per voxel. Where surfaces
facing the same way share a voxel, the front-most one is kept (glsl/voxelize/rasterize.frag). Light is
not part of it (passes/inject.py), so a light change never revoxelizes.

An update touches only the voxels of the draws that changed: it flags the voxels those draws
covered before and cover now, rebuilds just those voxels from every draw that reaches them, and
leaves the rest as it was. Integer sums make the result the same bits as a full voxelization.
Afterwards the covered-voxel list and the covered cells of every mip level are brought up to
date."""
import numpy as np

from ..constants import CELL_LIST_LEVELS, IMAGE_UNIT, SHADER_ENUMS, STORAGE_BINDING, TEXTURE_UNIT
from ..scene_gpu import vertex_extras
from ..voxel_grid import bind_image



class VoxelizePass:
    def __init__(self, ctx, programs, geometry):
        self.ctx = ctx
        self.geometry = geometry
        # Per whether the draw has vertex colours, a second texture coordinate set or texture
        # transforms (scene_gpu.vertex_extras).
        self.programs = {extras: programs.program({"VERTEX_EXTRAS": 1} if extras else None, vertex_shader="voxelize/rasterize.vert",
                                                  geometry_shader="voxelize/rasterize.geom", fragment_shader="voxelize/rasterize.frag")
                         for extras in (False, True)}
        self.mark_covered = programs.compute("voxelize/mark_covered.comp")
        self.resolve = programs.compute("voxelize/resolve_sums.comp")
        self.keep = programs.compute("voxelize/rebuild_covered_list.comp")
        self.cells = programs.compute("voxelize/list_cells.comp")
        self.clear_cells = programs.compute("voxelize/clear_cells.comp")

    def update(self, grid, update, draws):
        """Apply a changes.VoxelUpdate to the grid; `draws` are all of the frame's draws."""
        grid.touched.clear()
        grid.bind_sums()
        grid.touched.bind("TOUCHED")
        uniforms = grid.uniforms()
        if update.full:
            grid.covered.bind("COVERED")
            self.mark_covered.set(**uniforms)
            grid.dispatch(self.mark_covered, grid.covered.count)
            reaching, box = update.added, grid.bounds()
            self._rasterize(grid, reaching, "front", touched_only=False, box=box)
        else:
            self._rasterize(grid, update.removed + update.added, "mark", touched_only=False, box=grid.bounds())
            box = update.touched_bounds(margin=grid.voxel_size)
            reaching = [d for d in draws if np.all(d.bounds[0] <= box[1]) and np.all(d.bounds[1] >= box[0])]
            self._rasterize(grid, reaching, "front", touched_only=True, box=box)
        self._rasterize(grid, reaching, "add", touched_only=True, box=box)
        self._resolve_and_relist(grid)

    def _rasterize(self, grid, draws, stage, touched_only, box):
        """Rasterize the parts of `draws` inside the world `box` in one of the fragment stages."""
        grid.framebuffer.use()
        self.ctx.viewport = (0, 0, grid.n, grid.n)
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.CULL_FACE | self.ctx.BLEND)
        for extras, program in self.programs.items():
            subset = [draw for draw in draws if vertex_extras(draw) == extras]
            if subset:
                program.set(**grid.uniforms(), stage=SHADER_ENUMS["VOXELIZE"][stage], touched_only=touched_only)
                self.geometry.draw(program, subset, materials=True, box=box)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT)

    def _resolve_and_relist(self, grid):
        uniforms = grid.uniforms()
        touched = grid.touched.read_count()
        grid.covered_next.clear()
        grid.covered_next.bind("COVERED_NEXT")
        for unit, volume in (("ALBEDO_OUT", grid.albedo), ("NORMAL_OUT", grid.normal), ("EMISSION_OUT", grid.emission),
                             ("EMITTED_OUT", grid.emitted), ("TOUCHED_FACES_OUT", grid.faces)):
            bind_image(volume, IMAGE_UNIT[unit], read=unit == "ALBEDO_OUT")
        self.resolve.set(**uniforms)
        grid.dispatch(self.resolve, touched)
        # The previous covered list: keep the voxels still covered, empty the others.
        grid.covered.bind("COVERED")
        grid.albedo.use(TEXTURE_UNIT["VOXEL_ALBEDO"])
        grid.bind_faces()
        bind_image(grid.base, IMAGE_UNIT["BASE_OUT"])
        self.keep.set(**uniforms)
        grid.dispatch(self.keep, grid.covered.count)
        grid.replace_covered()
        self._relist_cells(grid)

    def _relist_cells(self, grid):
        """Zero the face views over the old covered cells of every level, then list the cells
        the covered voxels now reach, level after level."""
        uniforms = grid.uniforms()
        grid.cells.bind_to_storage_buffer(STORAGE_BINDING["CELLS"])
        for level in range(1, grid.mip_count):
            grid.bind_faces(level)
            self.clear_cells.set(**uniforms, level=level, first=grid.level_first[level])
            grid.dispatch(self.clear_cells, grid.level_counts[level])
        grid.cells.write(bytes(4 * CELL_LIST_LEVELS))
        grid.cell_generation += 1
        grid.covered.bind("COVERED")
        grid.cell_stamps.bind_to_storage_buffer(STORAGE_BINDING["CELL_STAMPS"])
        source_count = grid.covered.count
        for level in range(1, grid.mip_count):
            self.cells.set(**uniforms, level=level, source_first=grid.level_first[level - 1],
                           target_first=grid.level_first[level], stamp_first=grid.level_first[level],
                           generation=grid.cell_generation)
            grid.dispatch(self.cells, source_count)
            source_count = int(np.frombuffer(grid.cells.read(4, offset=4 * level), dtype="u4")[0])
            grid.level_counts[level] = source_count

    def release(self):
        for handle in (*self.programs.values(), self.mark_covered, self.resolve, self.keep, self.cells, self.clear_cells):
            handle.release()

