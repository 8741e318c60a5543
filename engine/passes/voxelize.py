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
read back from the GPU only where the host cannot bound it (engine/voxels/room.py)."""
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from ..core.constants import (DRAW_HELD, DRAW_TEST_BOX, DRAW_VIEW_SHIFT, LIST_GROUP, NO_MATERIAL, SHADER_ENUMS, VOXEL_FACES,
                              VOXEL_SIDES, VOXEL_SUM_CHANNELS)
from ..gpu.scene_buffers import DRAW_FLAGS, draw_records
from ..scene.changes import VoxelUpdate
from ..voxels.clipmap import entered_slabs
from ..voxels.grid import GridStorage, VoxelGrid, sum_room, volume_image
from ..voxels.room import CoveredBound
from .cull import DrawList, buffer_holding, view_records

GL_CLIP_DISTANCES = [0x3000 + plane for plane in range(6)]  # GL_CLIP_DISTANCE0..5: rasterize.geom's planes


class VoxelizePass:
    def __init__(self, ctx, programs, cull):
        self.ctx = ctx
        self.cull = cull
        # Per whether the draw has vertex colours, a second texture coordinate set or texture
        # transforms (scene_buffers.vertex_extras): the buckets of the draw lists.
        self.programs = [programs.program({"VERTEX_EXTRAS": 1} if extras else None, vertex_shader="voxelize/rasterize.vert",
                                          geometry_shader="voxelize/rasterize.geom", fragment_shader="voxelize/rasterize.frag",
                                          reads=("SSBO_DRAWS", "SSBO_HELD_DRAWS", "SSBO_DRAW_VIEWS", "SSBO_MATERIALS",
                                                 "TEX_MATERIAL_TEXTURES"),
                                          writes=("SSBO_VOXEL_SUMS", "SSBO_FRONT_KEYS", "SSBO_VOXEL_RECORD", "SSBO_TOUCHED_RECORDS",
                                                  "SSBO_TOUCHED"))
                         for extras in (False, True)]
        # What a voxelization draws: every draw into the jobs of rebuilt levels, to mark their
        # voxels (marking), and into every job, to sum them (jobs), each culled by the jobs'
        # boxes; and the moved draws as the voxels hold them and as they are, written by the
        # host, to mark the voxels they covered and cover (moved).
        bucket_of = lambda flags: ((flags & DRAW_FLAGS["extras"]) != 0).astype(np.int64)  # noqa: E731
        self.marking, self.jobs = (DrawList(ctx, bucket_of, 2) for _ in range(2))
        self.moved = DrawList(ctx, bucket_of, 2)
        self.held_draws = None  # the moved draws' records as the voxels hold them
        self.mark_covered = programs.compute("voxelize/mark_covered.comp", reads=("SSBO_COVERED",),
                                             writes=("SSBO_TOUCHED", "SSBO_VOXEL_RECORD", "SSBO_TOUCHED_RECORDS"))
        self.resolve = programs.compute(
            "voxelize/resolve_sums.comp", reads=("SSBO_TOUCHED",),
            writes=("SSBO_VOXEL_SUMS", "SSBO_FRONT_KEYS", "SSBO_TOUCHED_RECORDS", "SSBO_VOXEL_RECORD", "SSBO_RECORD_POOL", "SSBO_VOXEL_ALBEDO",
                    "SSBO_VOXEL_NORMAL", "SSBO_VOXEL_EMISSION", "SSBO_COVERED",
                    "SSBO_NEWLY_COVERED"))
        self.list_cells = programs.compute("voxelize/list_cells.comp", reads=("SSBO_COVERED",),
                                           writes=("SSBO_CELLS", "SSBO_CELL_STAMPS"))
        self.fill_emission = programs.compute("voxelize/fill_cone_emission.comp", reads=("SSBO_CELLS", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS),
                                              writes=("IMG_CONE_EMISSION_OUT",))
        self.clear_cells = programs.compute("voxel_grid/clear_cells.comp", reads=("SSBO_CELLS", "SSBO_SEGMENTS"), writes=("IMG_FACES_OUT",))
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
        self.sums = ctx.buffer(data=bytes(4 * VOXEL_SIDES * len(VOXEL_SUM_CHANNELS) * room))
        self.front_keys = ctx.buffer(data=bytes(4 * 2 * VOXEL_FACES * room))  # a key and a count per facing
        self.touched_records = ctx.buffer(reserve=4 * grid.touched_room)
        self.framebuffer = ctx.empty_framebuffer((n, n))
        self._scratch.hold((n, grid.levels, grid.touched_room), [self.sums, self.front_keys, self.touched_records, self.framebuffer])

    def _touching(self, grid):
        """What the passes that flag voxels as touched write: the touched list and the record
        index words the touched voxels had."""
        return dict(SSBO_TOUCHED=grid.touched.buffer, SSBO_VOXEL_RECORD=grid.records.index,
                    SSBO_TOUCHED_RECORDS=self.touched_records)

    def update(self, grid, update, buffers, bounds):
        """Apply a changes.VoxelUpdate to the grid, drawing the scene's draws (SceneBuffers);
        `bounds` are their world bounds ((D, 2, 3), the table's). Writes the grid's records and
        their surface, its touched, covered and cell lists (a new epoch), zeroes the light at
        the records it gave and the face views of the voxels it emptied; where the lists or the
        records were short of room, grows them and voxelizes every draw instead."""
        for level, shift in update.scrolled.items():
            self._scroll(grid, level, shift)
        bound = self.room.bound(grid, update)
        # Room enough for certain, nothing read back: a bound within the lists, and one chunk,
        # whose resolve frees records before it takes any (voxelize/resolve_sums.comp).
        if bound is not None and bound.fits(grid.list_room) and bound.touched <= sum_room(grid.n, grid.levels):
            self._apply(grid, update, buffers, bounds, bound.touched)
            self.room.voxelized(grid, update)
            return
        self._apply(grid, update, buffers, bounds)
        counts = grid.list_counts()
        while not counts.fits(grid.list_room):
            grid.grow_lists(counts.needed())
            update = VoxelUpdate(True, [], [])
            self._apply(grid, update, buffers, bounds)
            counts = grid.list_counts()
        self.room.voxelized(grid, update, counts.covered)

    def _scroll(self, grid, level, shift):
        """Scroll a level whose cube moved by `shift` of its voxels (grid.regions holds where it
        lies now): its emission cells are zeroed where they were (its face views, which
        FaceViewsPass writes, are zeroed by it before: clear_level), then its records move to
        their voxels' new coordinates, those it left behind freed. The covered list keeps its
        count; the voxelization of the slabs that follows gives it its new epoch."""
        if grid.cone_emission is not None:  # its level 1: the coarser ones are its hardware mips
            self.clear_cells.set(**grid.uniforms(), voxel_entries=False, views=1, cleared_levels=grid.level_mask([level]))
            grid.dispatch(self.clear_cells, grid.cells.segment(1), SSBO_CELLS=grid.cells.buffer,
                          IMG_FACES_OUT=volume_image(grid.cone_emission))
        self.scroll_level.set(**grid.uniforms(), scrolled_level=level, level_shift=tuple(int(s) for s in shift))
        for lifting in (True, False):
            self.scroll_level.set(lifting=lifting)
            grid.dispatch(self.scroll_level, grid.covered.segment(), SSBO_COVERED=grid.covered.buffer, **grid.records.resources())

    def _apply(self, grid, update, buffers, bounds, touched=None):
        """The update: flag and list the voxels to rebuild, then chunk after chunk of them sum
        their front layers and resolve. `touched`: at most how many voxels it touches, where the
        host knows (else the count is read back)."""
        self._ensure_scratch(grid)
        grid.touched.clear()
        grid.newly_covered.clear()
        rebuilt = frozenset(range(grid.levels)) if update.full else update.rebuilt_levels()
        if rebuilt:
            self.mark_covered.set(**grid.uniforms(), marked_levels=grid.level_mask(rebuilt))
            grid.dispatch(self.mark_covered, grid.covered.segment(), SSBO_COVERED=grid.covered.buffer, **self._touching(grid))
        jobs = _level_jobs(grid, update, rebuilt, bounds)
        marking = [job for job in jobs if job.marked == "every draw"]
        moving = [job for job in jobs if job.marked == "moved draws"]
        if marking:
            self._cull(self.marking, buffers, marking)
        if moving:
            self._write_moved(buffers, update, moving)
        with self._rasterizing(grid):
            if marking:
                self._rasterize(grid, "mark", self.marking, buffers, 0)
            if moving:
                self._rasterize(grid, "mark", self.moved, buffers, 0, self.held_draws)
            for job in jobs:
                if job.marked in (None, "every voxel"):
                    self._mark_box(grid, job.level, job.voxels)
            grid.size_list(grid.touched)
            listed = min(grid.touched.read_count() if touched is None else touched, grid.touched_room)
            if jobs:
                self._cull(self.jobs, buffers, jobs)
            for chunk_first in range(0, max(listed, 1), sum_room(grid.n, grid.levels)):
                if jobs:
                    for stage in ("front", "add"):
                        self._rasterize(grid, stage, self.jobs, buffers, chunk_first)
                self._resolve(grid, chunk_first)
        self._relist_covered(grid, frozenset(update.scrolled) if update.scrolls_only else None)
        if grid.cone_emission is not None:  # a scrolled level's cells all moved
            self.fill_cone_emission(grid, touched=not update.scrolled)

    def _cull(self, draw_list, buffers, jobs):
        """Cull every draw's clusters against the jobs' world boxes into `draw_list`."""
        draw_list.build(buffers)
        views = view_records(len(jobs))
        for view, job in zip(views, jobs):
            _job_view(view, job)
            view["items"] = (0, draw_list.item_count, DRAW_TEST_BOX, 0)
        self.cull.run(draw_list, buffers, views)

    def _write_moved(self, buffers, update, jobs):
        """The moved list: each draw the voxels held (its held record, not cut out) and each
        draw as it is now, whole, once into every job."""
        views = view_records(len(jobs))
        for view, job in zip(views, jobs):
            _job_view(view, job)
        self.moved.write_views(views)
        held = draw_records(np.array([draw.world for draw in update.removed]).reshape(-1, 4, 4), NO_MATERIAL,
                            [draw.posed for draw in update.removed])
        self.held_draws = buffer_holding(self.ctx, self.held_draws, held, keep=True)
        job_count = len(jobs)
        placed = [(index | DRAW_HELD, draw, 0) for index, draw in enumerate(update.removed)]
        placed += [(draw.index, draw, int((buffers.draw_flags[draw.index] & DRAW_FLAGS["extras"]) != 0)) for draw in update.added]
        placed.sort(key=lambda entry: entry[2])
        commands = np.zeros((len(placed), 5), np.uint32)
        instances = np.zeros(len(placed) * job_count, np.uint32)
        for k, (value, draw, _) in enumerate(placed):
            entry = draw.entry
            commands[k] = (entry.index_count, job_count, entry.first_index, entry.base_vertex, k * job_count)
            instances[k * job_count:(k + 1) * job_count] = value | (np.arange(job_count, dtype=np.uint32) << DRAW_VIEW_SHIFT)
        buckets = [bucket for _, _, bucket in placed]
        self.moved.write(commands, instances, [(buckets.index(b) if b in buckets else 0, buckets.count(b)) for b in (0, 1)])

    def _mark_box(self, grid, level, voxels):
        """Flag and list as touched every voxel of a box of a level ((lo, hi) in its coordinates)."""
        lo, hi = (np.asarray(corner, int) for corner in voxels)
        size = hi - lo
        self.mark_box.set(**grid.uniforms(), marked_level=level, box_min=tuple(int(c) for c in lo), box_size=tuple(int(c) for c in size))
        self.mark_box.run(-(-int(np.prod(size)) // LIST_GROUP), **self._touching(grid))
        grid.barrier()

    @contextmanager
    def _rasterizing(self, grid):
        """The raster state of the voxelization's draws, set once around all of them: its
        framebuffer of n x n without attachments, no depth test, culling or blending, the
        clip planes of the jobs' voxels (the compute passes between the draws ignore it)."""
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, grid.n, grid.n)
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.CULL_FACE | self.ctx.BLEND)
        for plane in GL_CLIP_DISTANCES:
            self.ctx.enable_direct(plane)
        try:
            yield
        finally:
            for plane in GL_CLIP_DISTANCES:
                self.ctx.disable_direct(plane)

    def _rasterize(self, grid, stage, draw_list, buffers, chunk_first, held_draws=None):
        """Rasterize a draw list in one of the fragment stages, into the sums of the chunk of the
        touched list from `chunk_first`: each instance into its job's level and voxels (the
        parts of the draws inside the job's world box, which the list was culled by)."""
        resources = {**buffers.records(), **buffers.textures.resources(), **self._touching(grid),
                     "SSBO_HELD_DRAWS": held_draws if held_draws is not None else buffers.draws,
                     "SSBO_DRAW_VIEWS": draw_list.views, "SSBO_VOXEL_SUMS": self.sums, "SSBO_FRONT_KEYS": self.front_keys}
        for bucket, program in enumerate(self.programs):
            if draw_list.bucket_ranges[bucket][1]:
                program.set(**grid.uniforms(), stage=SHADER_ENUMS["VOXELIZE"][stage], chunk_first=chunk_first)
                draw_list.draw(bucket, program, buffers, resources)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT)

    def _resolve(self, grid, chunk_first):
        """Resolve the sums of the chunk of touched voxels from `chunk_first` into the voxels'
        records: those emptied give theirs back, then the covered ones take theirs."""
        resources = {**self._touching(grid), **grid.surface(), "SSBO_RECORD_POOL": grid.records.pool, "SSBO_VOXEL_SUMS": self.sums,
                     "SSBO_FRONT_KEYS": self.front_keys, "SSBO_COVERED": grid.covered.buffer,
                     "SSBO_NEWLY_COVERED": grid.newly_covered.buffer}
        self.resolve.set(**grid.uniforms(), chunk_first=chunk_first)
        for freeing in (True, False):
            self.resolve.set(freeing=freeing)
            grid.dispatch(self.resolve, grid.touched.segment(), **resources)

    def fill_cone_emission(self, grid, touched=False):
        """Level 1 of the grid's cone emission volume from the voxels' emission: over every
        covered cell (a volume made zero), or over the cells of the voxels the last
        voxelization touched."""
        segment = grid.touched.segment() if touched else grid.cells.segment(1)
        self.fill_emission.set(**grid.uniforms(), voxel_entries=touched)
        grid.dispatch(self.fill_emission, segment, SSBO_CELLS=segment.buffer, **grid.surface(),
                      IMG_CONE_EMISSION_OUT=volume_image(grid.cone_emission))

    def build_emission_mips(self, grid):
        """The cone emission's coarser levels from its level 1, after a voxelization where
        surfaces emit."""
        grid.cone_emission.build_mipmaps()

    def _relist_covered(self, grid, scrolled_levels):
        """The newly covered list (whose records' light the grid zeroes next:
        VoxelGrid.zero_new_records) and the covered list (a voxel per record, which the resolve
        wrote) sized, the covered list's new epoch marked with the levels a scroll alone changed
        (Epoch.scrolled_levels), and the cells of every level listed again."""
        grid.size_list(grid.newly_covered)
        grid.covered_changed(scrolled_levels)
        self._relist_cells(grid)

    def _relist_cells(self, grid):
        """List the cells the covered voxels now reach, every level in one pass."""
        uniforms, cells = grid.uniforms(), grid.cells
        generation = cells.restart()
        self.list_cells.set(**uniforms, top_level=grid.mip_count - 1, level_first=cells.first_words(), generation=generation)
        grid.dispatch(self.list_cells, grid.covered.segment(), SSBO_COVERED=grid.covered.buffer, SSBO_CELLS=cells.buffer,
                      SSBO_CELL_STAMPS=cells.stamps)
        grid.size_cells()

    def memory_bytes(self):
        """GPU bytes of the scratch storage for the grid's size."""
        return self._scratch.memory_bytes()

    def release(self):
        for handle in (*self.programs, self.mark_covered, self.resolve,
                       self.list_cells, self.fill_emission, self.clear_cells, self.scroll_level, self.mark_box):
            handle.release()
        for draw_list in (self.marking, self.jobs, self.moved):
            draw_list.release()
        if self.held_draws is not None:
            self.held_draws.release()
        self._scratch.release()


@dataclass(frozen=True)
class Job:
    """A part of a voxelization: the voxels (lo, hi) of a level, in its coordinates, which the
    draws reaching the world `box` are drawn into; the ones marked there beforehand: those of
    "every draw", of the "moved draws", or every voxel of the box ("every voxel", or None for
    a scrolled level's slab, left out where no draw reaches it)."""
    level: int
    box: tuple
    voxels: tuple
    marked: str


def _level_jobs(grid, update, rebuilt, bounds):
    """What the update voxelizes, as Jobs: a rebuilt level, its whole cube, every draw marked. A
    level that scrolled (and is not rebuilt): each slab it took in, all its voxels marked.
    Elsewhere, the moved draws' voxels: the box within a voxel of the level of them, the moved
    draws marked, and every voxel of the box a moved posed draw held (its copy holds its new
    pose only). The world boxes hold a voxel more on each side: what a triangle's dilation
    reaches. A job that marks its box's voxels is left out where no draw (`bounds`: every
    draw's world box, (D, 2, 3)) reaches the box."""
    n, changed = grid.n, update.removed + update.added
    jobs = []
    for level in range(grid.levels):
        lo, hi = grid.level_bounds(level)
        voxel = grid.level_voxel_size(level)
        whole = (np.zeros(3, int), np.full(3, n))
        if level in rebuilt:
            boxes = [((lo, hi), whole, "every draw")]
        elif level in update.scrolled:
            boxes = [((lo + first * voxel - voxel, lo + last * voxel + voxel), (first, last), None)
                     for first, last in entered_slabs(update.scrolled[level], n)]
        elif changed:
            changed_box = update.touched_bounds(margin=voxel)
            boxes = [((np.maximum(changed_box[0], lo), np.minimum(changed_box[1], hi)), whole, "moved draws")]
            for draw in update.removed:  # a posed draw as the voxels hold it: every voxel of its box
                if draw.posed:
                    box = (np.maximum(draw.bounds[0] - voxel, lo), np.minimum(draw.bounds[1] + voxel, hi))
                    first = np.clip(np.floor((box[0] - lo) / voxel), 0, n).astype(int)
                    last = np.clip(np.ceil((box[1] - lo) / voxel), 0, n).astype(int)
                    boxes.append((box, (first, last), "every voxel"))
        else:
            continue
        for box, voxels, marked in boxes:
            if np.any(box[0] > box[1]):
                continue  # the change lies outside this level
            if marked is None and not np.any(np.all(bounds[:, 0] <= box[1], axis=1) & np.all(bounds[:, 1] >= box[0], axis=1)):
                continue  # a slab no surface reaches stays empty
            jobs.append(Job(level, box, voxels, marked))
    return jobs


def _job_view(view, job):
    """A DrawView record of a Job: its level, voxels and world box."""
    view["voxels_min"] = (*job.voxels[0], job.level)
    view["voxels_max"] = (*job.voxels[1], 0)
    view["box_min"][:3], view["box_max"][:3] = job.box
