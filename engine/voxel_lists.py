"""Lists of voxels on the GPU and the tokens that say what they hold.

- `VoxelList`: packed voxel coordinates after a count (covered, touched, stale voxels);
- `CellLists`: the covered cells of every mip level, listed level after level;
- `Epoch`: one state of the covered list (what was computed from it records its epoch);
- `ClassIndex`: where the covered voxels' interleave classes lie in a sorted list.
"""
from dataclasses import dataclass

import numpy as np

from .constants import CELL_LIST_LEVELS, STORAGE_BINDING


@dataclass(frozen=True)
class VoxelSegment:
    """Entries [first, first + count) of a GPU buffer of packed voxel coordinates: what the
    passes over a voxel list (injection, composition, the emitters' light) run over."""
    buffer: object
    first: int
    count: int


class Epoch:
    """A token for one state of the covered-voxel list: each rebuild of the list starts a new
    epoch after the one before. What was computed from the list (the gather anchors, the class
    index, the injected light) records the epoch it was computed for."""

    def __init__(self, previous=None):
        self.previous = previous

    def next(self):
        """The epoch after this one (which forgets its own predecessor: only the latest step
        is ever asked about)."""
        successor = Epoch(self)
        self.previous = None
        return successor

    def follows(self, earlier):
        """Whether this epoch comes right after `earlier` (exactly one rebuild since)."""
        return earlier is not None and self.previous is earlier


@dataclass(frozen=True)
class ClassIndex:
    """The covered voxels sorted into interleave classes for the progressive bounce
    (GatherPass.sort_classes): in `voxel_list` each class is one run, its gather anchors then
    its other voxels; in `cell_list` the covered level-1 cells one run per class, the cells of
    several classes last. Each segment (first, count). Valid for `epoch` and `interleave`."""

    epoch: Epoch
    interleave: int
    voxel_list: object
    classes: tuple       # (first, count) per class
    anchors: tuple       # per class: its anchors, which trace the gather
    filled: tuple        # per class: its voxels that take their gather from the anchors
    every: tuple         # every covered voxel
    cell_list: object
    cell_runs: tuple     # per class: the run of its level-1 cells
    mixed_cell_run: tuple  # the level-1 cells that hold voxels of several classes

    def sorted_for(self, epoch, interleave):
        return self.epoch is epoch and self.interleave == interleave

    def segment(self, class_index=None):
        """The voxels of an interleave class (None: every covered voxel)."""
        first, count = self.every if class_index is None else self.classes[class_index]
        return VoxelSegment(self.voxel_list, first, count)

    def anchor_segment(self, class_index):
        """The gather's anchors of an interleave class."""
        return VoxelSegment(self.voxel_list, *self.anchors[class_index])

    def filled_segment(self, class_index):
        """The voxels of an interleave class that interpolate the anchors."""
        return VoxelSegment(self.voxel_list, *self.filled[class_index])

    def cell_segments(self, class_index):
        """The level-1 cells an interleave class's voxels lie in: its own, then the mixed."""
        return [self.cell_runs[class_index], self.mixed_cell_run]


class VoxelList:
    """Packed voxel coordinates on the GPU (a count, then the entries); `count` is the host's
    copy, read back after the pass that appended."""

    def __init__(self, ctx, capacity):
        self.buffer = ctx.buffer(reserve=4 + 4 * capacity)
        self.count = 0

    def clear(self):
        self.buffer.write(bytes(4))
        self.count = 0

    def read_count(self):
        self.count = int(np.frombuffer(self.buffer.read(4), dtype="u4")[0])
        return self.count

    def segment(self):
        """Every entry, as a VoxelSegment (they follow the count)."""
        return VoxelSegment(self.buffer, 1, self.count)

    def bind(self, binding):
        self.buffer.bind_to_storage_buffer(STORAGE_BINDING[binding])

    def release(self):
        self.buffer.release()


class CellLists:
    """The covered cells of mip levels 1..log2 n in one buffer: a count per level
    (CELL_LIST_LEVELS of them), then the cells of each level in a run of its own; a stamp per
    cell and rebuild lists each cell once (voxelize/list_cells.comp). `counts[level]` is the
    host's copy of a level's count, read back after the pass that listed it."""

    def __init__(self, ctx, n):
        sizes = [(n >> level) ** 3 for level in range(n.bit_length())]
        self.first = [int(sum(sizes[1:level])) for level in range(len(sizes))]  # a level's first entry after the counts
        self.counts = [0] * len(sizes)
        self.buffer = ctx.buffer(data=bytes(4 * (CELL_LIST_LEVELS + sum(sizes[1:]))))
        self.stamps = ctx.buffer(data=bytes(4 * sum(sizes[1:])))
        self.generation = 0

    def segment(self, level):
        """(first, count) of a level's cells in the buffer (counts included)."""
        return CELL_LIST_LEVELS + self.first[level], self.counts[level]

    def restart(self):
        """Empty every level for a rebuild; returns the rebuild's stamp."""
        self.buffer.write(bytes(4 * CELL_LIST_LEVELS))
        self.generation += 1
        return self.generation

    def read_count(self, level):
        self.counts[level] = int(np.frombuffer(self.buffer.read(4, offset=4 * level), dtype="u4")[0])
        return self.counts[level]

    def bind(self):
        self.buffer.bind_to_storage_buffer(STORAGE_BINDING["CELLS"])

    def bind_stamps(self):
        self.stamps.bind_to_storage_buffer(STORAGE_BINDING["CELL_STAMPS"])

    def release(self):
        self.buffer.release()
        self.stamps.release()
