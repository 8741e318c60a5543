"""Lists of voxels on the GPU and the tokens that say what they hold.

- `VoxelList`: packed voxel coordinates after a count (covered, touched, stale voxels);
- `CellLists`: the covered cells of every mip level, listed level after level;
- `SegmentTable`: where segments of those lists lie and how large a dispatch over each is,
  as the GPU counted them: passes over a list are dispatched indirectly from its rows, so no
  frame reads a count back;
- `Epoch`: one state of the covered list (what was computed from it records its epoch);
- `ClassIndex`: where the covered voxels' interleave classes lie in a sorted list.
"""
import math
from dataclasses import dataclass

import numpy as np

from ..core.constants import CELL_LIST_LEVELS, CLASS_PARTS, LIST_GROUP, struct_dtype
from ..gpu.functions import write_buffer

SEGMENT = struct_dtype("ListSegment")


class SegmentTable:
    """Rows of GLSL_STRUCTS["ListSegment"], written on the GPU (voxel_grid/size_segment.comp,
    gather/scan_buckets.comp): each a segment of a list, its first entry and count, and the
    group count of an indirect dispatch over it."""

    def __init__(self, ctx, rows):
        self.buffer = ctx.buffer(data=bytes(SEGMENT.itemsize * rows))
        self.rows = rows

    def write(self, row, first, count):
        """Set a row from the host (a list it filled itself)."""
        entry = np.zeros((), SEGMENT)
        entry["dispatch"] = (math.ceil(count / LIST_GROUP), 1, 1, 0)
        entry["range"] = (first, count, 0, 0)
        write_buffer(self.buffer, entry.tobytes(), row * SEGMENT.itemsize)

    def memory_bytes(self):
        return self.buffer.size

    def read(self):
        """(first, count) of every row: a read back from the GPU, for inspection."""
        rows = np.frombuffer(self.buffer.read(), SEGMENT)
        return [(int(r["range"][0]), int(r["range"][1])) for r in rows]

    def release(self):
        self.buffer.release()


@dataclass(frozen=True)
class VoxelSegment:
    """A segment of a GPU buffer of packed voxel coordinates, row `row` of `table`: what the
    passes over a voxel list (injection, composition, the emitters' light) run over."""
    buffer: object
    table: SegmentTable
    row: int

    def read(self):
        """(first, count): a read back from the GPU, for inspection."""
        return self.table.read()[self.row]


class Epoch:
    """A token for one state of the covered-voxel list: each rebuild of the list starts a new
    epoch after the one before. What was computed from the list (the gather anchors, the class
    index, the injected light) records the epoch it was computed for. `scrolled_levels`: the
    levels a rebuild scrolled, where it changed nothing else (the voxels it touched lie in
    them); None: it may have changed any level."""

    def __init__(self, previous=None, scrolled_levels=None):
        self.previous = previous
        self.scrolled_levels = scrolled_levels

    def next(self, scrolled_levels=None):
        """The epoch after this one (which forgets its own predecessor: only the latest step
        is ever asked about)."""
        successor = Epoch(self, scrolled_levels)
        self.previous = None
        return successor

    def follows(self, earlier):
        """Whether this epoch comes right after `earlier` (exactly one rebuild since)."""
        return earlier is not None and self.previous is earlier


@dataclass(frozen=True)
class ClassIndex:
    """The covered voxels sorted into interleave classes for the progressive bounce
    (GatherPass.sort_classes): in `voxel_list` each class is one run, its gather anchors, the
    voxels that interpolate them, then those beneath a finer level; in `cell_list` the covered
    level-1 cells one run per class, the cells of several classes last. The segments are rows
    of `voxel_rows` and `cell_rows`, as sorted into `interleave` classes (the radiance schedule
    knows for which covered list)."""

    interleave: int
    levels: int
    voxel_list: object
    voxel_rows: SegmentTable  # every voxel; per class its voxels, anchors, interpolated ones; per level its voxels beneath a finer one
    cell_list: object
    cell_rows: SegmentTable   # per class the run of its level-1 cells; the mixed cells last

    @staticmethod
    def voxel_row_buckets(interleave, levels, buckets):
        """The buckets of the class sort each voxel row spans, [first, end): every voxel, per
        class its voxels, its anchors (part 0), the voxels that interpolate them (part 1),
        then per class and level its voxels beneath a finer level (part 2; a part holds
        `buckets`, level by level, as many to each)."""
        span, per_level = CLASS_PARTS * buckets, buckets // levels
        beneath_finer = [c * span + 2 * buckets + k * per_level for c in range(interleave) for k in range(levels)]
        return ([(0, interleave * span)] + [(c * span, (c + 1) * span) for c in range(interleave)]
                + [(c * span, c * span + buckets) for c in range(interleave)]
                + [(c * span + buckets, c * span + 2 * buckets) for c in range(interleave)]
                + [(b, b + per_level) for b in beneath_finer])

    def segment(self, class_index=None):
        """The voxels of an interleave class (None: every covered voxel)."""
        return VoxelSegment(self.voxel_list, self.voxel_rows, 0 if class_index is None else 1 + class_index)

    def anchor_segment(self, class_index):
        """The gather's anchors of an interleave class."""
        return VoxelSegment(self.voxel_list, self.voxel_rows, 1 + self.interleave + class_index)

    def filled_segment(self, class_index):
        """The voxels of an interleave class that interpolate the anchors."""
        return VoxelSegment(self.voxel_list, self.voxel_rows, 1 + 2 * self.interleave + class_index)

    def finer_segments(self, class_index=None):
        """The voxels beneath a finer level of an interleave class (None: of every class), by
        level: {level: [VoxelSegment, one a class]} for the levels above the finest."""
        classes = range(self.interleave) if class_index is None else [class_index]
        return {level: [self._finer_segment(c, level) for c in classes] for level in range(1, self.levels)}

    def _finer_segment(self, class_index, level):
        """A class's voxels of one level beneath a finer level, in the rows by level
        (voxel_row_buckets)."""
        row = 1 + 3 * self.interleave + class_index * self.levels + level
        return VoxelSegment(self.voxel_list, self.voxel_rows, row)

    def cell_segments(self, class_index):
        """The level-1 cells an interleave class's voxels lie in: its own, then the mixed."""
        return [VoxelSegment(self.cell_list, self.cell_rows, row) for row in (class_index, self.interleave)]


class VoxelList:
    """Packed voxel coordinates on the GPU: a count, then the entries; its segment row (every
    entry) is sized on the GPU after the passes that append (VoxelGrid.size_list)."""

    def __init__(self, ctx, capacity):
        self.buffer = ctx.buffer(reserve=4 + 4 * capacity)
        self.table = SegmentTable(ctx, 1)

    def clear(self):
        write_buffer(self.buffer, bytes(4))
        self.table.write(0, 1, 0)

    def memory_bytes(self):
        return self.buffer.size + self.table.memory_bytes()

    def read_count(self):
        """The number of entries: a read back from the GPU, for inspection."""
        return int(np.frombuffer(self.buffer.read(4), dtype="u4")[0])

    def read_entries(self):
        """The entries (packed voxels, uint32; the covered list's free records NO_VOXEL): a read
        back from the GPU, for inspection."""
        return np.frombuffer(self.buffer.read(4 * (1 + self.read_count())), dtype="u4")[1:].copy()

    def segment(self):
        """Every entry, as a VoxelSegment (they follow the count)."""
        return VoxelSegment(self.buffer, self.table, 0)

    def release(self):
        self.buffer.release()
        self.table.release()


class CellLists:
    """The covered cells of mip levels 1..log2 n (of every level of the grid) in one buffer: a count per level
    (CELL_LIST_LEVELS of them), then the cells of each level in a run of its own; a stamp per
    cell and rebuild lists each cell once (voxelize/list_cells.comp, every level in one pass). Row
    `level` of `table` is the level's segment, sized on the GPU after they are listed."""

    def __init__(self, ctx, n, levels):
        sizes = [levels * (n >> level) ** 3 for level in range(n.bit_length())]
        self.first = [int(sum(sizes[1:level])) for level in range(len(sizes))]  # a level's first entry after the counts
        self.buffer = ctx.buffer(data=bytes(4 * (CELL_LIST_LEVELS + sum(sizes[1:]))))
        self.stamps = ctx.buffer(data=bytes(4 * sum(sizes[1:])))
        self.table = SegmentTable(ctx, len(sizes))
        self.generation = 0

    def segment(self, level):
        """A level's cells (their first entry in the buffer, counts included)."""
        return VoxelSegment(self.buffer, self.table, level)

    def memory_bytes(self):
        return self.buffer.size + self.stamps.size + self.table.memory_bytes()

    def entries_first(self, level):
        return CELL_LIST_LEVELS + self.first[level]

    def first_words(self):
        """Each level's first entry after the counts, as the bytes of a uint[CELL_LIST_LEVELS]."""
        return np.array(self.first + [0] * (CELL_LIST_LEVELS - len(self.first)), "u4").tobytes()

    def restart(self):
        """Empty every level for a rebuild; returns the rebuild's stamp."""
        write_buffer(self.buffer, bytes(4 * CELL_LIST_LEVELS))
        self.generation += 1
        return self.generation

    def release(self):
        for resource in (self.buffer, self.stamps, self.table):
            resource.release()
