"""Voxelization pass: the scene's surfaces into the N^3 grid (geometry-shader dominant-axis
projection, conservative dilation, fixed-point sums with atomics), resolved into the grid's
surface volumes: albedo, mean normal, emission and surface offset per voxel. Where surfaces
facing the same way share a voxel, the front-most one is kept (glsl/voxelize/rasterize.frag). Light is
not part of it (passes/inject.py), so a light change never revoxelizes.

An update touches only the voxels of the draws that changed: it flags the voxels those draws
covered before and cover now, rebuilds just those voxels from every draw that reaches them, and
leaves the rest as it was. Integer sums make the result the same bits as a full voxelization.
Afterwards the covered-voxel list and the covered cells of every mip level are brought up to
date. Where the grid's lists had no room for the voxels an update listed, the grid grows its
lists (made anew, empty) and the whole scene is voxelized into it. Whether they had room is
read back from the GPU only where the host cannot bound it (engine/voxel_room.py)."""
import numpy as np

from ..constants import (GL_IMAGE_FORMAT, IMAGE_UNIT, SHADER_ENUMS, STORAGE_BINDING, TEXTURE_UNIT, VOXEL_FACES, VOXEL_SLABS,
                         VOXEL_SUM_CHANNELS)
from ..changes import VoxelUpdate
from ..scene_gpu import vertex_extras
from ..voxel_grid import GridStorage, bind_image
from ..voxel_room import CoveredBound


class VoxelizePass:
    def __init__(self, ctx, programs, geometry):
        self.ctx = ctx
        self.geometry = geometry
        # Per whether the draw has vertex colours, a second texture coordinate set or texture
        # transforms (scene_gpu.vertex_extras).
        self.programs = {extras: programs.program({"VERTEX_EXTRAS": 1} if extras else None, vertex_shader="voxelize/rasterize.vert",
                                                  geometry_shader="voxelize/rasterize.geom", fragment_shader="voxelize/rasterize.frag",
                                                  reads=("TEX_BASE_COLOR_MAP", "TEX_METAL_ROUGH_MAP", "TEX_EMISSIVE_MAP"),
                                                  writes=("SSBO_VOXEL_SUMS", "IMG_FRONT", "SSBO_TOUCHED"))
                         for extras in (False, True)}
        self.mark_covered = programs.compute("voxelize/mark_covered.comp", reads=("SSBO_COVERED",),
                                             writes=("SSBO_TOUCHED", "SSBO_VOXEL_SUMS"))
        self.resolve = programs.compute(
            "voxelize/resolve_sums.comp", reads=("SSBO_TOUCHED",),
            writes=("SSBO_VOXEL_SUMS", "IMG_FRONT", "IMG_ALBEDO_OUT", "IMG_NORMAL_OUT", "IMG_EMISSION_OUT", "IMG_CONE_EMISSION_OUT",
                    "IMG_TOUCHED_FACES_OUT", "SSBO_COVERED_NEXT"))
        self.rebuild_covered = programs.compute("voxelize/rebuild_covered_list.comp", reads=("SSBO_COVERED", "TEX_VOXEL_ALBEDO"),
                                                writes=("SSBO_COVERED_NEXT", "IMG_BASE_OUT", "IMG_FACES_OUT"))
        self.list_cells = programs.compute("voxelize/list_cells.comp", reads=("SSBO_COVERED",),
                                           writes=("SSBO_CELLS", "SSBO_CELL_STAMPS"))
        self.clear_cells = programs.compute("voxelize/clear_cells.comp", reads=("SSBO_CELLS",), writes=("IMG_FACES_OUT",))
        self._scratch = GridStorage()  # the fixed-point sums, front-layer keys, a framebuffer
        self.room = CoveredBound()     # what is known of the grid's covered count

    def _ensure_scratch(self, n):
        """For an n^3 grid's slabs of n / VOXEL_SLABS layers: the sums, one storage buffer per
        channel (lib/voxel_sums.glsl), and the front-layer keys, per voxel and facing direction
        (stacked like the face views): zero, and zero again after each slab's resolve
        (voxelize/resolve_sums.comp)."""
        if self._scratch.holds(n):
            return
        self._scratch.release()
        ctx, depth = self.ctx, n // VOXEL_SLABS
        voxels = n * n * depth
        self.sums = [ctx.buffer(data=bytes(4 * voxels)) for _ in VOXEL_SUM_CHANNELS]
        self.front = ctx.texture3d((n, n, VOXEL_FACES * depth), 1, data=bytes(4 * VOXEL_FACES * voxels), dtype="u4")
        self.framebuffer = ctx.empty_framebuffer((n, n))
        self._scratch.hold(n, [*self.sums, self.front, self.framebuffer])

    def _bind_sums(self):
        for channel, buffer in enumerate(self.sums):
            buffer.bind_to_storage_buffer(STORAGE_BINDING["VOXEL_SUMS"] + channel)
        self.front.bind_to_image(IMAGE_UNIT["FRONT"], read=True, write=True, format=GL_IMAGE_FORMAT["r32ui"])

    def update(self, grid, update, draws):
        """Apply a changes.VoxelUpdate to the grid; `draws` are all of the frame's draws.
        Writes the grid's surface volumes, its touched, covered and cell lists (a new epoch),
        and zeroes the face views and base radiance of the voxels it emptied; where the lists
        were short of room, grows them and voxelizes every draw instead."""
        bound = self.room.needed(grid, update, draws)
        self._apply(grid, update, draws)
        if bound is not None and bound <= grid.list_room:  # room enough for certain: nothing read back
            self.room.voxelized(grid, draws)
            return
        needed, covered = grid.list_need()
        while needed > grid.list_room:
            grid.grow_lists(needed)
            self._scratch.release()  # the voxels left off the touched list are still flagged
            self._apply(grid, VoxelUpdate(True, [], list(draws)), draws)
            needed, covered = grid.list_need()
        self.room.voxelized(grid, draws, covered)

    def _apply(self, grid, update, draws):
        """The update, slab after slab (those it reaches): flag the voxels to rebuild, sum their
        front layers, resolve."""
        self._ensure_scratch(grid.n)
        grid.touched.clear()
        grid.covered_next.clear()
        self._bind_sums()
        grid.touched.bind("TOUCHED")
        if update.full:
            box, reaching = grid.bounds(), update.added
        else:
            box = update.touched_bounds(margin=grid.voxel_size)
            reaching = [d for d in draws if np.all(d.bounds[0] <= box[1]) and np.all(d.bounds[1] >= box[0])]
        for slab_first, slab_box in self._slabs(grid, box):
            slab = dict(slab_first=slab_first, slab_depth=grid.n // VOXEL_SLABS)
            if update.full:
                grid.covered.bind("COVERED")
                self.mark_covered.set(**grid.uniforms(), **slab)
                grid.dispatch(self.mark_covered, grid.covered.segment())
                self._rasterize(grid, reaching, "front", False, slab_box, slab)
            else:
                self._rasterize(grid, update.removed + update.added, "mark", False, slab_box, slab)
                self._rasterize(grid, reaching, "front", True, slab_box, slab)
            self._rasterize(grid, reaching, "add", True, slab_box, slab)
            grid.size_list(grid.touched)
            self._resolve(grid, slab)
        self._relist_covered(grid)

    def _slabs(self, grid, box):
        """(first layer, world box) of each slab that together hold the layers the world `box`
        reaches, from its first layer on; the slab's box grown by two voxels, which the
        voxelizer's dilation may reach past a triangle, for culling."""
        depth, (lo, hi), size = grid.n // VOXEL_SLABS, grid.bounds(), grid.voxel_size
        first = int(np.clip(np.floor((box[0][2] - lo[2]) / size), 0, grid.n - 1))
        last = int(np.clip(np.floor((box[1][2] - lo[2]) / size), first, grid.n - 1))
        for slab_first in range(first, last + 1, depth):
            z0, z1 = lo[2] + slab_first * size, lo[2] + (slab_first + depth) * size
            yield slab_first, (np.maximum(box[0], [lo[0], lo[1], z0 - 2 * size]), np.minimum(box[1], [hi[0], hi[1], z1 + 2 * size]))

    def _rasterize(self, grid, draws, stage, touched_only, box, slab):
        """Rasterize the parts of `draws` inside the world `box` in one of the fragment stages,
        into the sums of the slab `slab` (its slab_first and slab_depth)."""
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, grid.n, grid.n)
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.CULL_FACE | self.ctx.BLEND)
        for extras, program in self.programs.items():
            subset = [draw for draw in draws if vertex_extras(draw) == extras]
            if subset:
                program.set(**grid.uniforms(), **slab, stage=SHADER_ENUMS["VOXELIZE"][stage], touched_only=touched_only)
                self.geometry.draw(program, subset, materials=True, box=box)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT)

    def _resolve(self, grid, slab):
        """Resolve the sums of the voxels of the slab `slab` the update touched into the surface
        volumes."""
        grid.covered_next.bind("COVERED_NEXT")
        for unit, volume in (("ALBEDO_OUT", grid.albedo), ("NORMAL_OUT", grid.normal), ("EMISSION_OUT", grid.emission),
                             ("CONE_EMISSION_OUT", grid.cone_emission), ("TOUCHED_FACES_OUT", grid.faces)):
            bind_image(volume, IMAGE_UNIT[unit], read=unit == "ALBEDO_OUT")
        self.resolve.set(**grid.uniforms(), **slab)
        grid.dispatch(self.resolve, grid.touched.segment())

    def _relist_covered(self, grid):
        """The covered list from the previous one (the voxels still covered kept, the others
        emptied) and the resolve's new voxels; then the cells of every level."""
        grid.covered.bind("COVERED")
        grid.albedo.use(TEXTURE_UNIT["VOXEL_ALBEDO"])
        grid.bind_faces()
        bind_image(grid.base, IMAGE_UNIT["BASE_OUT"])
        self.rebuild_covered.set(**grid.uniforms())
        grid.dispatch(self.rebuild_covered, grid.covered.segment())
        grid.replace_covered()
        self._relist_cells(grid)

    def _relist_cells(self, grid):
        """Zero the face views over the old covered cells of every level, then list the cells
        the covered voxels now reach, level after level."""
        uniforms, cells = grid.uniforms(), grid.cells
        cells.bind()
        for level in range(1, grid.mip_count):
            grid.bind_faces(level)
            self.clear_cells.set(**uniforms, level=level, first=cells.first[level])
            grid.dispatch(self.clear_cells, cells.segment(level))
        generation = cells.restart()
        grid.covered.bind("COVERED")
        cells.bind_stamps()
        source = grid.covered.segment()
        for level in range(1, grid.mip_count):
            self.list_cells.set(**uniforms, level=level, source_first=cells.first[level - 1],
                                target_first=cells.first[level], stamp_first=cells.first[level], generation=generation)
            grid.dispatch(self.list_cells, source)
            grid.size_cells(level)
            source = cells.segment(level)

    def memory_bytes(self):
        """GPU bytes of the scratch storage for the grid's size."""
        return self._scratch.memory_bytes()

    def release(self):
        for handle in (*self.programs.values(), self.mark_covered, self.resolve, self.rebuild_covered, self.list_cells, self.clear_cells):
            handle.release()
        self._scratch.release()

