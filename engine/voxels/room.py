"""How many voxels a voxelization may list, bounded on the host, so that an update whose lists
provably have room reads nothing back from the GPU (the viewer's frames stay without a sync).
GL-free.

A voxelization rasterizes each triangle once along one axis, one fragment per pixel of its
projected bounding box grown by half a pixel (glsl/voxelize/rasterize.geom), each fragment in
one voxel: so a draw covers at most `fragment_bound` voxels. The voxels covered after an
update lie in those covered when they were last counted by the draws that have not changed
since, or in those the changed draws cover now: at most the count plus the changed draws'
bounds. An update lists as touched the voxels its removed draws covered and its added draws
cover: at most their bounds; a scroll, every voxel of the slabs its levels took in (each of
which it may cover)."""
from dataclasses import dataclass

import numpy as np

from ..core import transforms
from .clipmap import entered_slabs


def fragment_bound(draw, lo, voxel_size, n):
    """At most how many voxels of the n^3 grid from `lo` with voxels of `voxel_size` the draw's
    triangles cover: per triangle, the pixels of its bounding box's largest projection, grown
    by half a pixel on each side, clipped to the grid. The sum counts the voxels triangles share
    once per triangle, so a fine mesh is bounded by its box instead, grown by two voxels on
    each side: a fragment lies within a voxel of its triangle's box across the projection and
    within two along it (the dilated corners' depth is extrapolated along the plane)."""
    positions = (transforms.transform_points(draw.world, draw.mesh_arrays[0]) - lo) / voxel_size
    corners = positions[np.asarray(draw.mesh_arrays[2], np.int64)]          # (T, 3 corners, 3 axes)
    first, last = np.floor(corners.min(axis=1)), np.floor(corners.max(axis=1))
    pixels = np.clip(np.minimum(last, n - 1) - np.maximum(first, 0) + 2, 0, n)  # per axis, half a pixel each side
    pixels[np.any((last < 0) | (first > n - 1), axis=1)] = 0                    # wholly outside the grid
    projections = np.stack([pixels[:, 1] * pixels[:, 2], pixels[:, 0] * pixels[:, 2], pixels[:, 0] * pixels[:, 1]], axis=1)
    box = np.clip(np.minimum(last.max(axis=0), n - 1) - np.maximum(first.min(axis=0), 0) + 5, 0, n)  # two voxels each side
    return int(min(projections.max(axis=1).sum(), np.prod(box)))


@dataclass(frozen=True)
class ListBound:
    """At most how many voxels an update leaves covered and how many it touches; read back
    after it, also how many records the grid's pool was short (engine/voxels/records.py)."""
    covered: int
    touched: int
    records_short: int = 0

    def needed(self):
        """The list room (in covered voxels) that holds them: the touched list has twice it."""
        return max(self.covered, -(-self.touched // 2))

    def fits(self, room):
        """Whether a grid with list room `room` held the update: its lists, and records for
        its voxels."""
        return self.needed() <= room and not self.records_short


class CoveredBound:
    """What is known of a grid's covered count: the count last read back, the draws placed
    anew since (changes.PlacedDraw, by index), and the epoch of the covered list the voxelizer
    left after it (an epoch that is not the grid's current one means the grid was rebuilt by
    someone else: nothing is known)."""

    def __init__(self):
        self.epoch = None
        self.covered = 0
        self.placed = {}   # draw index -> PlacedDraw: the draws that moved since the count
        self._bounds = {}  # (positions, indices, world, grid's levels) -> (positions, indices, bound)

    def bound(self, grid, update):
        """The ListBound of `update` (a changes.VoxelUpdate) to the grid; None where nothing is
        known."""
        if update.full or update.levels or (update.scrolled and not update.scrolls_only) or self.epoch is not grid.epoch:
            return None
        placed = dict(self.placed)
        placed.update((draw.index, draw) for draw in update.added)
        # A scroll alone marks every voxel of the slabs its levels took in, and may cover each.
        entered = sum(int(np.prod(hi - lo)) for shift in update.scrolled.values() for lo, hi in entered_slabs(shift, grid.n))
        return ListBound(covered=self.covered + entered + sum(self._bound(d, grid) for d in placed.values()),
                         touched=entered + sum(self._bound(d, grid) for d in update.removed + update.added))

    def _bound(self, draw, grid):
        """The draw's fragment_bound summed over the grid's levels (it is rasterized into each)."""
        positions, indices = draw.mesh_arrays[0], draw.mesh_arrays[2]
        levels = [(grid.level_bounds(level)[0], grid.level_voxel_size(level)) for level in range(grid.levels)]
        key = (id(positions), id(indices), draw.world.tobytes(), grid.n, tuple((lo.tobytes(), size) for lo, size in levels))
        entry = self._bounds.get(key)
        if entry is None or entry[0] is not positions or entry[1] is not indices:
            bound = sum(fragment_bound(draw, lo, size, grid.n) for lo, size in levels)
            entry = self._bounds[key] = (positions, indices, bound)
        return entry[2]

    def voxelized(self, grid, update, covered=None):
        """After `update` voxelized the grid: `covered` the count read back, or None where it
        was not (the bound carries on from the last count, with the update's draws)."""
        self.epoch = grid.epoch
        if covered is not None:
            self.covered, self.placed = covered, {}
        else:
            self.placed.update((draw.index, draw) for draw in update.added)
        live = {(id(d.mesh_arrays[0]), id(d.mesh_arrays[2]), d.world.tobytes()) for d in self.placed.values()}
        self._bounds = {key: entry for key, entry in self._bounds.items() if key[:3] in live}
