"""Voxelization pass: the scene's surfaces into the N^3 grid (geometry-shader dominant-axis
projection, conservative dilation, fixed-point sums with atomics), resolved into the grid's
surface volumes: albedo, mean normal, emission and surface offset per voxel. Where surfaces
facing the same way share a voxel, the front-most one is kept (glsl/voxelize/rasterize.frag). Light is
not part of it (passes/inject.py), so a light change never revoxelizes.

An update touches only the voxels of the draws that changed and of the levels that moved with
the camera: it flags the voxels those draws covered before and cover now (and every voxel those
levels covered and now cover), rebuilds just those voxels from every draw that reaches them, and
leaves the rest as it was. A level that moved by part of its cube scrolls instead: its voxels
keep their records (and so their surface and light) at their new coordinates, and only the slabs
it took in are voxelized, every voxel of a slab flagged at once instead of by drawing its
triangles a third time (while draws change too, the whole level is rebuilt after the scroll).
Integer sums make the result the same bits as a full voxelization.
Afterwards the covered-voxel list and the covered cells of every mip level are brought up to
date. Where the grid's lists had no room for the voxels an update listed, the grid grows its
lists (made anew, empty) and the whole scene is voxelized into it. Whether they had room is
read back from the GPU only where the host cannot bound it (engine/voxel_room.py)."""
import numpy as np

from ..constants import LIST_GROUP, SHADER_ENUMS, VOXEL_FACES, VOXEL_SUM_CHANNELS
from ..changes import VoxelUpdate
from ..gl_bindings import bind_storage
from ..scene_gpu import vertex_extras
from ..voxel_grid import GridStorage, VoxelGrid, bind_values, bind_volume, sum_room
from ..voxel_room import CoveredBound

GL_CLIP_DISTANCES = [0x3000 + plane for plane in range(6)]  # GL_CLIP_DISTANCE0..5: rasterize.geom's planes


class VoxelizePass:
    def __init__(self, ctx, programs, geometry):
        self.ctx = ctx
        self.geometry = geometry
        # Per whether the draw has vertex colours, a second texture coordinate set or texture
        # transforms (scene_gpu.vertex_extras).
        self.programs = {extras: programs.program({"VERTEX_EXTRAS": 1} if extras else None, vertex_shader="voxelize/rasterize.vert",
                                                  geometry_shader="voxelize/rasterize.geom", fragment_shader="voxelize/rasterize.frag",
                                                  reads=("TEX_BASE_COLOR_MAP", "TEX_METAL_ROUGH_MAP", "TEX_EMISSIVE_MAP"),
                                                  writes=("SSBO_VOXEL_SUMS", "SSBO_FRONT_KEYS", "SSBO_VOXEL_RECORD", "SSBO_TOUCHED_RECORDS",
                                                          "SSBO_TOUCHED"))
                         for extras in (False, True)}
        self.mark_covered = programs.compute("voxelize/mark_covered.comp", reads=("SSBO_COVERED",),
                                             writes=("SSBO_TOUCHED", "SSBO_VOXEL_RECORD", "SSBO_TOUCHED_RECORDS"))
        self.resolve = programs.compute(
            "voxelize/resolve_sums.comp", reads=("SSBO_TOUCHED",),
            writes=("SSBO_VOXEL_SUMS", "SSBO_FRONT_KEYS", "SSBO_TOUCHED_RECORDS", "SSBO_VOXEL_RECORD", "SSBO_RECORD_POOL", "SSBO_VOXEL_ALBEDO",
                    "SSBO_VOXEL_NORMAL", "SSBO_VOXEL_EMISSION", "SSBO_COVERED",
                    "SSBO_NEWLY_COVERED"))
        self.clear_new_records = programs.compute(
            "voxelize/clear_new_records.comp", reads=("SSBO_NEWLY_COVERED", "SSBO_VOXEL_RECORD"),
            writes=("SSBO_VOXEL_BASE", "SSBO_VOXEL_GATHERED", "SSBO_GATHERED_OUT", "SSBO_VOXEL_REFLECTED", "SSBO_VOXEL_EMITTER_IRRADIANCE",
                    "SSBO_VOXEL_SKY_IRRADIANCE", "SSBO_VOXEL_TRACED_SKY_IRRADIANCE"))
        self.list_cells = programs.compute("voxelize/list_cells.comp", reads=("SSBO_COVERED",),
                                           writes=("SSBO_CELLS", "SSBO_CELL_STAMPS"))
        self.fill_emission = programs.compute("voxelize/fill_cone_emission.comp", reads=("SSBO_CELLS", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS),
                                              writes=("IMG_CONE_EMISSION_OUT",))
        self.clear_cells = programs.compute("voxelize/clear_cells.comp", reads=("SSBO_CELLS", "SSBO_SEGMENTS"), writes=("IMG_FACES_OUT",))
        self.scroll_level = programs.compute("voxelize/scroll_level.comp", writes=("SSBO_COVERED", "SSBO_VOXEL_RECORD", "SSBO_RECORD_POOL"))
        self.mark_box = programs.compute("voxelize/mark_voxel_box.comp", writes=("SSBO_TOUCHED", "SSBO_VOXEL_RECORD", "SSBO_TOUCHED_RECORDS"))
        self._scratch = GridStorage()  # the fixed-point sums, front-layer keys, touched voxels' records, a framebuffer
        self.room = CoveredBound()     # what is known of the grid's covered count

    def _ensure_scratch(self, grid):
        """For the grid's size and list room: the sums of a chunk of the touched list (sum_room
        voxels, a record of VOXEL_SUM_CHANNELS each) and their front-layer keys (VOXEL_FACES
        each), zero, and zero again after each chunk's resolve (voxelize/resolve_sums.comp);
        and the words of the record index the touched voxels had (lib/voxel_slots.glsl)."""
        n = grid.n
        if self._scratch.holds((n, grid.levels, grid.touched_room)):
            return
        self._scratch.release()
        ctx, room = self.ctx, sum_room(n, grid.levels)
        self.sums = ctx.buffer(data=bytes(4 * len(VOXEL_SUM_CHANNELS) * room))
        self.front_keys = ctx.buffer(data=bytes(4 * VOXEL_FACES * room))
        self.touched_records = ctx.buffer(reserve=4 * grid.touched_room)
        self.framebuffer = ctx.empty_framebuffer((n, n))
        self._scratch.hold((n, grid.levels, grid.touched_room), [self.sums, self.front_keys, self.touched_records, self.framebuffer])

    def _bind_scratch(self, grid):
        for name, buffer in (("VOXEL_SUMS", self.sums), ("FRONT_KEYS", self.front_keys), ("TOUCHED_RECORDS", self.touched_records)):
            bind_storage(buffer, name)
        grid.records.bind()

    def update(self, grid, update, draws):
        """Apply a changes.VoxelUpdate to the grid; `draws` are all of the frame's draws.
        Writes the grid's records and their surface, its touched, covered and cell lists (a
        new epoch), zeroes the light at the records it gave and the face views of the voxels it
        emptied; where the lists or the records were short of room, grows them and voxelizes
        every draw instead."""
        for level, shift in update.scrolled.items():
            self._scroll(grid, level, shift)
        bound = self.room.bound(grid, update, draws)
        # Room enough for certain, nothing read back: a bound within the lists, and one chunk,
        # whose resolve frees records before it takes any (voxelize/resolve_sums.comp).
        if bound is not None and bound.fits(grid.list_room) and bound.touched <= sum_room(grid.n, grid.levels):
            self._apply(grid, update, draws, bound.touched)
            self.room.voxelized(grid, draws)
            return
        self._apply(grid, update, draws)
        counts = grid.list_counts()
        while not counts.fits(grid.list_room):
            grid.grow_lists(counts.needed())
            self._apply(grid, VoxelUpdate(True, [], list(draws)), draws)
            counts = grid.list_counts()
        self.room.voxelized(grid, draws, counts.covered)

    def _scroll(self, grid, level, shift):
        """Scroll a level whose cube moved by `shift` of its voxels (grid.regions holds where it
        lies now): its face views and emission cells are zeroed where they were, then its
        records move to their voxels' new coordinates, those it left behind freed. The covered
        list keeps its count; the voxelization of the slabs that follows gives it its new
        epoch."""
        cells, mask = grid.cells, grid.level_mask([level])
        volumes = [(grid.faces, VOXEL_FACES, grid.mip_count)]  # (volume, its views, the mip levels held up to)
        if grid.cone_emission is not None:
            volumes.append((grid.cone_emission, 1, 2))  # its level 1: the coarser ones are its hardware mips
        for volume, views, mips in volumes:
            for mip in range(1, mips):
                bind_volume(volume, "FACES_OUT", level=mip - 1)
                bind_storage(cells.segment(mip).buffer, "CELLS")
                self.clear_cells.set(**grid.uniforms(), level=mip, entry_level=mip, views=views, cleared_levels=mask)
                grid.dispatch(self.clear_cells, cells.segment(mip))
        grid.records.bind()
        grid.covered.bind("COVERED")
        self.scroll_level.set(**grid.uniforms(), scrolled_level=level, level_shift=tuple(int(s) for s in shift))
        for lifting in (True, False):
            self.scroll_level.set(lifting=lifting)
            grid.dispatch(self.scroll_level, grid.covered.segment())

    def _apply(self, grid, update, draws, touched=None):
        """The update: flag and list the voxels to rebuild, then chunk after chunk of them sum
        their front layers and resolve. `touched`: at most how many voxels it touches, where the
        host knows (else the count is read back)."""
        self._ensure_scratch(grid)
        grid.touched.clear()
        grid.newly_covered.clear()
        self._bind_scratch(grid)
        grid.touched.bind("TOUCHED")
        rebuilt = frozenset(range(grid.levels)) if update.full else update.rebuilt_levels()
        if rebuilt:
            grid.covered.bind("COVERED")
            self.mark_covered.set(**grid.uniforms(), marked_levels=grid.level_mask(rebuilt))
            grid.dispatch(self.mark_covered, grid.covered.segment())
        jobs = _level_jobs(grid, update, rebuilt, draws)
        self._rasterize(grid, "mark", [(level, box, voxels, marked) for level, box, voxels, marked, _ in jobs if marked is not None], 0)
        for level, _, voxels, marked, _ in jobs:
            if marked is None:
                self._mark_box(grid, level, voxels)
        grid.size_list(grid.touched)
        listed = min(grid.touched.read_count() if touched is None else touched, grid.touched_room)
        for chunk_first in range(0, max(listed, 1), sum_room(grid.n, grid.levels)):
            for stage in ("front", "add"):
                self._rasterize(grid, stage, [(level, box, voxels, reaching) for level, box, voxels, _, reaching in jobs], chunk_first)
            self._resolve(grid, chunk_first)
        self._relist_covered(grid, update.full, frozenset(update.scrolled) if update.scrolls_only else None)
        if grid.cone_emission is not None:  # a scrolled level's cells all moved
            self.fill_cone_emission(grid, touched=not update.scrolled)

    def _mark_box(self, grid, level, voxels):
        """Flag and list as touched every voxel of a box of a level ((lo, hi) in its coordinates)."""
        lo, hi = (np.asarray(corner, int) for corner in voxels)
        size = hi - lo
        self.mark_box.set(**grid.uniforms(), marked_level=level, box_min=tuple(int(c) for c in lo), box_size=tuple(int(c) for c in size))
        self.mark_box.program.run(-(-int(np.prod(size)) // LIST_GROUP))
        grid.barrier()

    def _rasterize(self, grid, stage, jobs, chunk_first):
        """Rasterize in one of the fragment stages, into the sums of the chunk of the touched
        list from `chunk_first`: for each (level, world box, voxel box, draws) of `jobs`, the
        parts of the draws inside the world box into the voxels of the voxel box ((lo, hi) in
        the level's coordinates) of that level."""
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, grid.n, grid.n)
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.CULL_FACE | self.ctx.BLEND)
        for plane in GL_CLIP_DISTANCES:
            self.ctx.enable_direct(plane)
        for extras, program in self.programs.items():
            program.set(**grid.uniforms(), stage=SHADER_ENUMS["VOXELIZE"][stage], chunk_first=chunk_first)
            for level, box, (voxels_lo, voxels_hi), draws in jobs:
                subset = [draw for draw in draws if vertex_extras(draw) == extras]
                if subset:
                    program.set(voxelize_level=level, voxelized_min=tuple(voxels_lo), voxelized_max=tuple(voxels_hi))
                    self.geometry.draw(program, subset, materials=True, box=box)
        for plane in GL_CLIP_DISTANCES:
            self.ctx.disable_direct(plane)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT)

    def _resolve(self, grid, chunk_first):
        """Resolve the sums of the chunk of touched voxels from `chunk_first` into the voxels'
        records: those emptied give theirs back, then the covered ones take theirs."""
        grid.covered.bind("COVERED")
        grid.newly_covered.bind("NEWLY_COVERED")
        grid.records.bind()
        for name, values in (("VOXEL_ALBEDO", grid.albedo), ("VOXEL_NORMAL", grid.normal), ("VOXEL_EMISSION", grid.emission)):
            bind_values(values, name)
        self.resolve.set(**grid.uniforms(), chunk_first=chunk_first)
        for freeing in (True, False):
            self.resolve.set(freeing=freeing)
            grid.dispatch(self.resolve, grid.touched.segment())

    def fill_cone_emission(self, grid, touched=False):
        """Level 1 of the grid's cone emission volume from the voxels' emission: over every
        covered cell (a volume made zero), or over the cells of the voxels the last
        voxelization touched."""
        grid.use_surface()
        segment = grid.touched.segment() if touched else grid.cells.segment(1)
        bind_storage(segment.buffer, "CELLS")
        bind_volume(grid.cone_emission, "CONE_EMISSION_OUT")
        self.fill_emission.set(**grid.uniforms(), entry_level=0 if touched else 1)
        grid.dispatch(self.fill_emission, segment)

    def _relist_covered(self, grid, full, scrolled_levels):
        """The light at the records the resolve gave zeroed; the covered list (a voxel per
        record, which the resolve wrote) sized, its new epoch marked with the levels a scroll
        alone changed (Epoch.scrolled_levels), and the cells of every level listed again."""
        grid.size_list(grid.newly_covered)
        for name, values in (("VOXEL_BASE", grid.base), ("VOXEL_GATHERED", grid.gathered[0]), ("GATHERED_OUT", grid.gathered[1]),
                             ("VOXEL_REFLECTED", grid.reflected),
                             ("VOXEL_EMITTER_IRRADIANCE", grid.emitter_irradiance), ("VOXEL_SKY_IRRADIANCE", grid.sky_irradiance),
                             ("VOXEL_TRACED_SKY_IRRADIANCE", grid.traced_sky_irradiance)):
            if values is not None:
                bind_values(values, name)
        self.clear_new_records.set(**grid.uniforms(), voxel_emitters=grid.emitter_irradiance is not None,
                                   voxel_sky=grid.sky_irradiance is not None)
        grid.dispatch(self.clear_new_records, grid.newly_covered.segment())
        grid.covered_changed(scrolled_levels)
        self._relist_cells(grid, full, zeroed=scrolled_levels is not None)

    def _relist_cells(self, grid, full, zeroed=False):
        """Zero the face views of every level over the cells the voxelization changed (those
        holding the voxels it touched; after a full one, the old covered cells) unless they are
        zero (`zeroed`: a scroll alone, which zeroed its levels' face views), then list the
        cells the covered voxels now reach, level after level."""
        uniforms, cells = grid.uniforms(), grid.cells
        for level in range(1, grid.mip_count) if not zeroed else ():
            grid.bind_faces(level)
            segment = cells.segment(level) if full else grid.touched.segment()
            bind_storage(segment.buffer, "CELLS")
            self.clear_cells.set(**uniforms, level=level, entry_level=level if full else 0, views=VOXEL_FACES,
                                 cleared_levels=grid.level_mask())
            grid.dispatch(self.clear_cells, segment)
        cells.bind()
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
        for handle in (*self.programs.values(), self.mark_covered, self.resolve, self.clear_new_records,
                       self.list_cells, self.fill_emission, self.clear_cells, self.scroll_level, self.mark_box):
            handle.release()
        self._scratch.release()


def _level_jobs(grid, update, rebuilt, draws):
    """What the update voxelizes: (level, world box, voxel box, the draws whose voxels there are
    flagged (None: every voxel of the box is), the draws that reach them), the voxel box
    (lo, hi) in the level's coordinates. A rebuilt level: its whole cube, every draw. A level
    that scrolled (and is not rebuilt): each slab it took in, all its voxels flagged. Elsewhere,
    the changed draws' voxels: the box within a voxel of the level of them, which the draws
    inside it reach. The world boxes hold a voxel more on each side: what a triangle's dilation
    reaches."""
    n, changed = grid.n, update.removed + update.added
    jobs = []
    for level in range(grid.levels):
        lo, hi = grid.level_bounds(level)
        voxel = grid.level_voxel_size(level)
        whole = (np.zeros(3, int), np.full(3, n))
        if level in rebuilt:
            boxes = [((lo, hi), whole, draws)]
        elif level in update.scrolled:
            boxes = [((lo + first * voxel - voxel, lo + last * voxel + voxel), (first, last), None)
                     for first, last in entered_slabs(update.scrolled[level], n)]
        elif changed:
            changed_box = update.touched_bounds(margin=voxel)
            boxes = [((np.maximum(changed_box[0], lo), np.minimum(changed_box[1], hi)), whole, changed)]
        else:
            continue
        for box, voxels, marked in boxes:
            if np.any(box[0] > box[1]):
                continue  # the change lies outside this level
            reaching = [d for d in draws if np.all(d.bounds[0] <= box[1]) and np.all(d.bounds[1] >= box[0])]
            if marked is None and not reaching:
                continue  # a slab no surface reaches stays empty
            jobs.append((level, box, voxels, marked, reaching))
    return jobs


def entered_slabs(shift, n):
    """The voxels a level of n^3 that scrolled by `shift` of its voxels took in, as disjoint
    boxes (lo, hi) in its new coordinates: along each axis that moved, the slab past the voxels
    it kept, across the axes before it only over the voxels kept along them."""
    lo, hi = np.zeros(3, int), np.full(3, n)
    slabs = []
    for axis, step in enumerate(int(s) for s in shift):
        if step == 0:
            continue
        first, last = lo.copy(), hi.copy()
        kept = (0, n - step) if step > 0 else (-step, n)
        first[axis], last[axis] = (n - step, n) if step > 0 else (0, -step)
        slabs.append((first, last))
        lo[axis], hi[axis] = kept
    return slabs
