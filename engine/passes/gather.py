"""The diffuse gather of the voxels: the anchors (1 in 4 of a surface's voxels, and those with
no anchor of a like facing around them: glsl/lib/gather_anchors.glsl) trace the lecture's 6
cones from their surface point through the face views, G = sum_j w_j L(p, w_j), and the other
voxels interpolate theirs; a clipmap level's voxels beneath the finer level take the mean of
the finer voxels that tile them, level by level from the finest. A bounce is a gather followed
by composing the face views again (passes/faces.py); the image interpolates the gathers per
pixel (passes/cone_trace.py). Also sorts the covered voxels into interleave classes for the
progressive bounce, each its anchors, the voxels that interpolate them, then those beneath a
finer level, and the covered level-1 cells by class, and closes the bounce series by
extrapolation."""
import numpy as np

from ..core.constants import CLASS_BLOCK, CLASS_FACINGS, CLASS_PARTS, MAX_INTERLEAVE, MAX_SEGMENT_ROWS
from ..gpu.functions import write_buffer
from ..voxels.clipmap import with_coarser_levels
from ..voxels.grid import GridStorage, VoxelGrid
from ..voxels.lists import ClassIndex, SegmentTable, VoxelList
from ..voxels.records import RecordArrays


def class_buckets(grid):
    """The buckets of the class sort per class and part: a (block, facing) each, the blocks of
    every level."""
    return grid.levels * max(grid.n // CLASS_BLOCK, 1) ** 3 * CLASS_FACINGS


class AnchorFill:
    """Values that anchors computed, spread to the other voxels: interpolated from the anchors
    around each voxel (lib/gather_anchors.glsl), then, beneath a finer level, the mean of the
    finer voxels that tile it, level after level. The gather uses it, and the sky's light the
    same way; each pass holds its own, over its own array."""

    def __init__(self, programs):
        self.fill_program = programs.compute("gather/interpolate_from_anchors.comp", writes=("SSBO_GATHERED_OUT",),
                                             reads=("SSBO_CLASS_LIST", "SSBO_SEGMENTS", "SSBO_GATHER_ANCHORS", *VoxelGrid.SURFACE_READS))
        self.take_finer_program = programs.compute("gather/take_finer_gather.comp", writes=("SSBO_GATHERED_OUT",),
                                                   reads=("SSBO_CLASS_LIST", "SSBO_SEGMENTS", "SSBO_GATHER_ANCHORS",
                                                          *VoxelGrid.SURFACE_READS))

    def run(self, grid, values, anchors, filled, finer, part=0, parts=1):
        """Interpolate `values` (an array per record, the anchors' values written) at the
        voxels of segment `filled` that are not anchors (a class's that interpolate, or the
        touched voxels; run `part` of `parts` of them) from the anchors around them (`anchors`:
        GatherPass.anchors), then, with the last run, at those beneath a finer level take the
        finer voxels' mean, level after level: `finer` maps each level above the finest to the
        segments holding them (a class's, every class's, or the touched voxels again). Returns
        `values`."""
        filling = dict(SSBO_GATHER_ANCHORS=anchors, **grid.surface(), SSBO_GATHERED_OUT=values)
        self.fill_program.set(**grid.uniforms(), segment_part=part, segment_parts=parts)
        grid.dispatch(self.fill_program, filled, SSBO_CLASS_LIST=filled.buffer, **filling)
        if part < parts - 1:
            return values
        for level in range(1, grid.levels):
            self.take_finer_program.set(**grid.uniforms(), level=level)
            for segment in finer[level]:
                grid.dispatch(self.take_finer_program, segment, SSBO_CLASS_LIST=segment.buffer, **filling)
        return values

    def release(self):
        self.fill_program.release()
        self.take_finer_program.release()


class GatherPass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        # The anchors' cones, by whether the scene has a sky (SKY: they read its open share).
        trace_reads = ("SSBO_CLASS_LIST", "SSBO_SEGMENTS", "SSBO_GATHER_ANCHORS", *VoxelGrid.CONE_READS)
        self.trace_programs = {sky: programs.compute("gather/trace_anchor_cones.comp", {"SKY": 1} if sky else None,
                                                     reads=trace_reads + (("SSBO_VOXEL_SKY_IRRADIANCE",) if sky else ()),
                                                     writes=("SSBO_GATHERED_OUT",))
                               for sky in (False, True)}
        self.mark_stale_program = programs.compute("gather/mark_stale_anchors.comp", reads=("SSBO_TOUCHED", *VoxelGrid.SURFACE_READS),
                                                   writes=("SSBO_GATHER_ANCHORS", "SSBO_STALE_VOXELS"))
        self.find_anchors_program = programs.compute(
            "gather/find_anchors.comp", writes=("SSBO_GATHER_ANCHORS",),
            reads=("SSBO_COVERED", "SSBO_STALE_VOXELS", *VoxelGrid.SURFACE_READS))
        self.sort_classes_program = programs.compute(
            "gather/sort_classes.comp", reads=("SSBO_COVERED", "SSBO_GATHER_ANCHORS", *VoxelGrid.SURFACE_READS),
            writes=("SSBO_CLASS_BUCKETS", "SSBO_CLASS_LIST", "SSBO_CELL_CLASS_BITS"))
        self.sort_cells_program = programs.compute("gather/sort_class_cells.comp", reads=("SSBO_CELLS", "SSBO_CELL_CLASS_BITS"),
                                                   writes=("SSBO_CLASS_BUCKETS", "SSBO_CELLS_BY_CLASS"))
        self.filling = AnchorFill(programs)
        self.scan_program = programs.compute("gather/scan_buckets.comp", writes=("SSBO_CLASS_BUCKETS", "SSBO_SEGMENTS"))
        self.extrapolate_program = programs.compute("gather/close_bounce_series.comp", reads=("SSBO_COVERED", "SSBO_VOXEL_RECORD", "SSBO_VOXEL_GATHERED"),
                                                    writes=("SSBO_GATHERED_OUT",))
        self.anchors_epoch = None  # the epoch of the covered list self.anchors was found for
        self._storage = GridStorage()
        self.values = RecordArrays(2)  # the diffuse light each voxel gathered, per record: the latest and the one before

    def hold(self, records):
        """Hold the gather arrays for the grid's `records` (zero when made); True when made now."""
        return self.values.hold(records)

    @property
    def gathered(self):
        """The two gather arrays per record (the radiance schedule names which is the latest)."""
        return self.values.arrays

    def _ensure_storage(self, grid):
        """Per record of the grid (engine/voxels/records.py, the list room): its voxel's anchors
        (lib/gather_anchors.glsl); the list of covered voxels whose anchors to find again; the
        covered voxels sorted by class and the covered level-1 cells sorted by class (what a
        ClassIndex points into); the buckets of those counting sorts, and the classes of the
        voxels in each level-1 cell."""
        n, levels = grid.n, grid.levels
        if self._storage.holds((n, levels, grid.list_room)):
            return
        self._storage.release()
        ctx, cells = self.ctx, levels * (n >> 1) ** 3
        self.anchors = ctx.buffer(reserve=4 * grid.list_room)
        self.stale = VoxelList(ctx, grid.list_room)
        self.class_list = ctx.buffer(reserve=4 * grid.list_room)
        self.class_buckets = ctx.buffer(reserve=4 * CLASS_PARTS * MAX_INTERLEAVE * class_buckets(grid))
        self.cell_class_bits = ctx.buffer(reserve=4 * cells)
        self.cells_by_class = ctx.buffer(reserve=4 * cells)
        self.voxel_rows, self.cell_rows = SegmentTable(ctx, MAX_SEGMENT_ROWS), SegmentTable(ctx, MAX_INTERLEAVE + 1)
        self._storage.hold((n, levels, grid.list_room), [self.anchors, self.stale, self.class_list, self.class_buckets, self.cell_class_bits,
                               self.cells_by_class, self.voxel_rows, self.cell_rows])
        self.anchors_epoch = None

    def memory_bytes(self):
        """GPU bytes of the per-voxel storage for the grid's size and of the gather arrays."""
        return self._storage.memory_bytes() + self.values.memory_bytes()

    def read_anchors(self):
        """Per record, its voxel's anchor word (lib/gather_anchors.glsl): a read back, for
        inspection."""
        return np.frombuffer(self.anchors.read(), "u4").copy()

    def sort_classes(self, grid, interleave):
        """Sort the covered voxels into `interleave` classes, each its anchors, the voxels that
        interpolate them, then those beneath a finer level, grouped by block and facing,
        finding the anchors first where the voxels changed, and the covered level-1 cells by
        class: counting sorts whose prefix sums and segments the GPU computes
        (gather/scan_buckets.comp). Returns the ClassIndex of the sorted lists."""
        self._ensure_storage(grid)
        buckets = class_buckets(grid)
        total = interleave * CLASS_PARTS * buckets
        self.find_anchors(grid)
        write_buffer(self.class_buckets, bytes(4 * total))
        write_buffer(self.cell_class_bits, bytes(self.cell_class_bits.size))
        sort = dict(SSBO_COVERED=grid.covered.buffer, SSBO_GATHER_ANCHORS=self.anchors, **grid.surface(),
                    SSBO_CLASS_BUCKETS=self.class_buckets, SSBO_CLASS_LIST=self.class_list, SSBO_CELL_CLASS_BITS=self.cell_class_bits)
        self.sort_classes_program.set(**grid.uniforms(), interleave=interleave, scatter=False)
        grid.dispatch(self.sort_classes_program, grid.covered.segment(), **sort)
        self._scan(grid, total, self.voxel_rows, ClassIndex.voxel_row_buckets(interleave, grid.levels, buckets))
        self.sort_classes_program.set(scatter=True)
        grid.dispatch(self.sort_classes_program, grid.covered.segment(), **sort)
        self._sort_cells(grid, interleave)
        return ClassIndex(interleave=interleave, levels=grid.levels, voxel_list=self.class_list, voxel_rows=self.voxel_rows,
                          cell_list=self.cells_by_class, cell_rows=self.cell_rows)

    def _sort_cells(self, grid, interleave):
        """Sort the covered level-1 cells by the class of their voxels (marked by the voxel
        sort), the cells of several classes last, into self.cells_by_class: a row of
        self.cell_rows per class, then the mixed cells'."""
        buckets = interleave + 1
        write_buffer(self.class_buckets, bytes(4 * buckets))
        sort = dict(SSBO_CELLS=grid.cells.buffer, SSBO_CELL_CLASS_BITS=self.cell_class_bits, SSBO_CLASS_BUCKETS=self.class_buckets,
                    SSBO_CELLS_BY_CLASS=self.cells_by_class)
        self.sort_cells_program.set(**grid.uniforms(), first=grid.cells.first[1], interleave=interleave, scatter=False)
        grid.dispatch(self.sort_cells_program, grid.cells.segment(1), **sort)
        self._scan(grid, buckets, self.cell_rows, [(c, c + 1) for c in range(buckets)])
        self.sort_cells_program.set(scatter=True)
        grid.dispatch(self.sort_cells_program, grid.cells.segment(1), **sort)

    def _scan(self, grid, bucket_count, table, row_buckets):
        """Each of the first `bucket_count` buckets' counts becomes its first entry, and row r
        of `table` the segment of buckets row_buckets[r] = (first, end)."""
        rows = np.zeros((MAX_SEGMENT_ROWS, 2), "u4")
        rows[:len(row_buckets)] = row_buckets
        self.scan_program.set(bucket_count=bucket_count, row_count=len(row_buckets), row_buckets=rows.tobytes())
        self.scan_program.run(1, SSBO_CLASS_BUCKETS=self.class_buckets, SSBO_SEGMENTS=table.buffer)
        grid.barrier()

    def find_anchors(self, grid):
        """The anchor records of the grid's voxels, when the records were found for the epoch
        before: again for the voxels of the levels a scroll alone changed (their voxels moved,
        some neighbours left) and of the next coarser ones (which of their voxels lie beneath
        the finer level changed), or else for those around the voxels the last voxelization
        touched (self.stale); for every covered voxel otherwise."""
        self._ensure_storage(grid)
        if self.anchors_epoch is grid.epoch:
            return
        follows = grid.epoch.follows(self.anchors_epoch)
        scrolled = grid.epoch.scrolled_levels if follows else None
        every_voxel = not follows or scrolled is not None
        voxels = grid.covered.segment()
        marked = dict(**grid.surface(), SSBO_GATHER_ANCHORS=self.anchors, SSBO_STALE_VOXELS=self.stale.buffer)
        if not every_voxel:
            self.stale.clear()
            self.mark_stale_program.set(**grid.uniforms())
            grid.dispatch(self.mark_stale_program, grid.touched.segment(), SSBO_TOUCHED=grid.touched.buffer, **marked)
            grid.size_list(self.stale)
            voxels = self.stale.segment()
        found_levels = grid.level_mask() if scrolled is None else grid.level_mask(with_coarser_levels(scrolled, grid.levels))
        self.find_anchors_program.set(**grid.uniforms(), every_voxel=every_voxel, found_levels=found_levels)
        grid.dispatch(self.find_anchors_program, voxels, SSBO_COVERED=grid.covered.buffer, **marked)
        self.anchors_epoch = grid.epoch

    def run(self, grid, cones, cone_uniforms, out, anchors, filled, finer, sky_irradiance=None, part=0, parts=1):
        """Gather the anchors among the voxels of segment `anchors` (an interleave class's
        anchors, of the class index, or the touched voxels) through `cones` (what cones read:
        FaceViewsPass.cones) into `out` (one of self.gathered), then the others
        from them (`fill`); under a sky, `sky_irradiance` (SkyLightPass.irradiance) says how
        much of each side's hemisphere is open (glsl/gather/trace_anchor_cones.comp). Of each
        segment, run `part` of `parts` equal runs of its entries (the same share of the anchors
        and of the others: the same region of the grid). Every level's anchors in one
        dispatch: on a GPU a dispatch a level waits for each level's longest cones in turn.
        Returns `out`."""
        program = self.trace_programs[sky_irradiance is not None]
        program.set(**grid.uniforms(), **cone_uniforms, segment_part=part, segment_parts=parts)
        sky = {} if sky_irradiance is None else {"SSBO_VOXEL_SKY_IRRADIANCE": sky_irradiance}
        grid.dispatch(program, anchors, SSBO_CLASS_LIST=anchors.buffer, SSBO_GATHER_ANCHORS=self.anchors, **cones,
                      SSBO_GATHERED_OUT=out, **sky)
        return self.fill(grid, out, filled, finer, part, parts)

    def fill(self, grid, out, filled, finer, part=0, parts=1):
        """Interpolate `out` (one of self.gathered, the anchors' gathers written) at the
        voxels of segment `filled` that are not anchors (a class's that interpolate, or the
        touched voxels) from the anchors around them, then at those beneath a finer level take
        the finer voxels' mean, level after level: `finer` maps each level above the finest to
        the segments holding them (a class's, every class's, or the touched voxels again). Run
        `part` of `parts` of `filled`, the levels' means with the last (AnchorFill). Returns
        `out`."""
        return self.filling.run(grid, out, self.anchors, filled, finer, part, parts)

    def extrapolate(self, grid, latest, older, gain):
        """older <- latest + (latest - older) * gain, per covered voxel; returns `older`."""
        self.extrapolate_program.set(**grid.uniforms(), gain=tuple(float(g) for g in gain))
        grid.dispatch(self.extrapolate_program, grid.covered.segment(), SSBO_COVERED=grid.covered.buffer,
                      SSBO_VOXEL_RECORD=grid.records.index, SSBO_VOXEL_GATHERED=latest, SSBO_GATHERED_OUT=older)
        return older

    def release(self):
        self.values.release()
        for handle in (*self.trace_programs.values(), self.mark_stale_program, self.find_anchors_program, self.sort_classes_program,
                       self.sort_cells_program, self.filling, self.extrapolate_program, self.scan_program):
            handle.release()
        self._storage.release()
