"""Per-voxel data of the covered voxels: a record each, so that the grid's per-voxel values
take room for the voxels surfaces cover rather than for all n^3 (glsl/lib/voxel_records.glsl).

- `index`: per voxel of the grid (of every level), its record + 1, or 0 where no surface covers it;
- `pool`: the records no voxel holds, a stack: its height (int), how many records a
  voxelization asked of it in vain (uint), then the free records;
- the arrays of values (`array()`): an RGBA16F value per record and side (VOXEL_SIDES: a
  voxel's surfaces by orientation), two halves to a uint.

The voxelizer's resolve (glsl/voxelize/resolve_sums.comp) gives a voxel a record from the pool
when a surface first covers it and returns it when the last one leaves; a voxel keeps its
record, and so its values, while it stays covered. The pool has room for as many records as
the grid's lists have for covered voxels."""
import numpy as np

from ..core.constants import VOXEL_SIDES

VALUE_BYTES = 8  # an RGBA16F value
POOL_HEADER = 2  # the stack's height, the records asked for in vain


class RecordArrays:
    """Arrays of one value per record that a pass owns and writes (its light or radiance at the
    covered voxels): made zero for each records store of a grid (a new grid, or one made anew
    with more room), none while the pass does not want them."""

    def __init__(self, count):
        self.count = count
        self.records = None  # the VoxelRecords they were made for
        self.arrays = []

    def hold(self, records, wanted=True):
        """Hold the arrays for `records` (zero when made), none where not `wanted`; True when
        made now (what they held is still to compute)."""
        if not wanted:
            self.release()
            return False
        if self.records is records:
            return False
        self.release()
        self.arrays = [records.array() for _ in range(self.count)]
        self.records = records
        return True

    def memory_bytes(self):
        return sum(array.size for array in self.arrays)

    def release(self):
        for array in self.arrays:
            array.release()
        self.arrays, self.records = [], None


def pool_words(room, held=0):
    """The pool of `room` records of which the first `held` are held: the free ones stacked so
    that the next taken is the lowest."""
    return np.concatenate([[room - held, 0], np.arange(room - 1, held - 1, -1), np.zeros(held)]).astype("i4")


class VoxelRecords:
    """The records of the covered voxels of a grid of `levels` levels of n^3: room for `room` of
    them."""

    def __init__(self, ctx, n, levels, room):
        self.ctx, self.n, self.levels, self.room = ctx, n, levels, room
        self.index = ctx.buffer(data=bytes(4 * levels * n ** 3))
        self.pool = ctx.buffer(data=pool_words(room).tobytes())

    def array(self):
        """An array of values, one per record and side, zero."""
        return self.ctx.buffer(data=bytes(VALUE_BYTES * VOXEL_SIDES * self.room))

    def resources(self):
        """The index and the pool, as a program that hands out or frees records binds them."""
        return {"SSBO_VOXEL_RECORD": self.index, "SSBO_RECORD_POOL": self.pool}

    def hold(self, coords):
        """Give the voxels at `coords` (k, 3: x, y, z) records 0..k-1, in order, as a grid
        made by hand holds them (VoxelGrid.load)."""
        n = self.n
        index = np.zeros(self.levels * n ** 3, "u4")
        x, y, z = np.asarray(coords, np.int64).reshape(-1, 3).T
        index[x + n * (y + n * z)] = np.arange(1, len(x) + 1)
        self.index.write(index.tobytes())
        self.pool.write(pool_words(self.room, len(x)).tobytes())

    def read_index(self):
        """Per voxel of every level, its record + 1 (0: none): a read back, for inspection."""
        return np.frombuffer(self.index.read(), "u4").copy()

    def read_pool(self):
        """The pool's words (height, records asked for in vain, the free records): a read back,
        for inspection."""
        return np.frombuffer(self.pool.read(), "i4").copy()

    def read_counts(self):
        """How many records voxels hold, and how many the last voxelizations asked the pool for
        in vain (a read back)."""
        free_count, short = np.frombuffer(self.pool.read(8), "i4")
        return self.room - int(free_count), int(short)

    def memory_bytes(self):
        return self.index.size + self.pool.size

    def release(self):
        self.index.release()
        self.pool.release()
