"""The voxel grid: every GPU resource of the N^3 grid in one object, owned by the renderer and
passed to the passes that read and write it.

- the voxelizer's fixed-point sums, one storage buffer per channel (lib/voxel_sums.glsl), and
  its front-layer keys, per voxel and facing direction (stacked like the face views);
- the resolved surface of each voxel: albedo, mean normal, emission and surface offset; and
  `emitted` (emission, a = 1 where covered) with its hardware mip chain, the emission specular
  cones see;
- `emitter_light`: the emitters' shadowed irradiance at each voxel's surface and the fraction
  of it that arrives; `sky_light`: the environment's irradiance there, through the voxels, and
  `sky_traced`, the same as the anchors' cones brought it, before it is averaged;
- the radiance: `base` (emission + injected direct light), the diffuse `gathered` by each
  voxel (two volumes, the latest and the one before, for closing the bounce series), and the
  six one-sided face views cones read, stacked along z in one volume `faces` (n x n x 6n,
  view f at z in [f n, (f + 1) n)), with their mip chain;
- lists of voxels: `covered` (surface voxels), `touched` (by the last voxelization), the covered
  cells of every mip level, the covered voxels sorted by interleave class and, within a class,
  into the gather's anchors and the others, and the covered level-1 cells sorted by class;
  per voxel, whether it is an anchor and the anchors around it.

Every volume starts zero and every empty voxel stays zero: passes touch only listed voxels.
The covered list's state is an `Epoch`, a new one at each rebuild (`replace_covered`): what is
computed from the list records the epoch it was computed for, and "exactly one rebuild since"
is `grid.epoch.follows(recorded)`. Where the class list's segments lie is the `ClassIndex`
that GatherPass.sort_classes returns, held by the bounce schedule.
"""
import math
from dataclasses import dataclass

import numpy as np

from .constants import (CELL_LIST_LEVELS, CLASS_BLOCK, CLASS_FACINGS, CLASS_PARTS, GL_IMAGE_FORMAT, GRID_SIZES, IMAGE_UNIT, LIST_GROUP, MAX_INTERLEAVE, STORAGE_BINDING, TEXTURE_UNIT,
                        VOLUME_GROUP, VOXEL_FACES, VOXEL_FORMAT, VOXEL_MEMORY_BUDGET, VOXEL_SUM_CHANNELS)
from .errors import VctError

TEXEL_BYTES = 8  # RGBA16F
MIP_CHAIN = 8 / 7  # a full mip chain adds a seventh


def voxel_memory_bytes(n):
    """GPU bytes a grid of n^3 needs: sums, volumes (surface, radiance, faces with mips) and lists."""
    voxels = n ** 3
    sums = 4 * len(VOXEL_SUM_CHANNELS) + 4 * VOXEL_FACES  # and the front-layer keys
    surface = TEXEL_BYTES * (3 * MIP_CHAIN + 1)              # albedo, normal (viewable), emitted; emission
    radiance = TEXEL_BYTES * (MIP_CHAIN + 4)                 # base (viewable), two gathers, emitters' and sky light
    faces = TEXEL_BYTES * VOXEL_FACES * MIP_CHAIN
    lists = 6 * 4 + 2 * 4 / 7 + 2 * 4 / 8                    # touched, covered x2, stale, classes, anchors; cells, stamps;
                                                             # level-1 cells' classes, cells by class
    return int(voxels * (sums + surface + radiance + faces + lists))


def check_grid(ctx, n, source=None):
    """Refuse a grid size before anything is allocated."""
    if n not in GRID_SIZES:
        raise VctError(f"grid must be a power of two from {GRID_SIZES[0]} to {GRID_SIZES[-1]}, got {n}", source=source, field="grid")
    max_size = ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", 2048)
    if n > max_size:
        raise VctError(f"grid {n} exceeds GL_MAX_3D_TEXTURE_SIZE {max_size}", source=source, field="grid")
    need = voxel_memory_bytes(n)
    if need > VOXEL_MEMORY_BUDGET:
        raise VctError(f"grid {n} needs {need / 2**30:.1f} GiB of voxel memory, over the budget of "
                       f"{VOXEL_MEMORY_BUDGET / 2**30:.1f} GiB", source=source, field="grid")


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


class VoxelGrid:
    def __init__(self, ctx):
        self.ctx = ctx
        self.n = 0
        self.region = None
        self._resources = []
        self.epoch = Epoch()  # of the covered list: a new one whenever it is rebuilt (replace_covered)
        self.emitting = False  # whether any surface emits (`emitted` has its mip chain, `emitter_light` holds their light)
        self.sky_lit = False   # whether the scene has an environment (`sky_light` holds its light)

    # -- allocation ----------------------------------------------------------------------

    def ensure(self, n, region, source=None):
        """Hold an empty n^3 grid over `region` unless it already does; True when (re)made."""
        if n == self.n and self.region is not None and _same_region(region, self.region):
            return False
        check_grid(self.ctx, n, source)
        self.release()
        self._allocate(n)
        self.region = region
        return True

    def _allocate(self, n):
        ctx = self.ctx
        self.n = n
        voxels = n ** 3
        self.sums = [self._keep(ctx.buffer(data=bytes(4 * voxels))) for _ in VOXEL_SUM_CHANNELS]
        self.front = self._keep(ctx.texture3d((n, n, VOXEL_FACES * n), 1, data=bytes(4 * VOXEL_FACES * voxels), dtype="u4"))
        self.albedo, self.normal, self.base = (self._volume(mipmapped=True) for _ in range(3))
        self.emission = self._volume()
        self.emitted = self._volume(mipmapped=True)
        self.gathered = [self._volume() for _ in range(2)]
        self.emitter_light = self._volume()
        self.sky_light, self.sky_traced = self._volume(), self._volume()
        self.faces = self._volume(mipmapped=True, views=VOXEL_FACES)
        self.touched, self.covered, self.covered_next = (self._keep(VoxelList(ctx, voxels)) for _ in range(3))
        self.stale = self._keep(VoxelList(ctx, voxels))  # whose gather-anchor records to find again
        # Covered cells of levels 1..log2(n), one segment per level after a count per level.
        sizes = [(n >> level) ** 3 for level in range(self.mip_count)]
        self.level_first = [int(sum(sizes[1:level])) for level in range(self.mip_count)]
        self.level_counts = [0] * self.mip_count
        self.cells = self._keep(ctx.buffer(data=bytes(4 * (CELL_LIST_LEVELS + sum(sizes[1:])))))
        self.cell_stamps = self._keep(ctx.buffer(data=bytes(4 * sum(sizes[1:]))))
        self.cell_generation = 0
        # Covered voxels sorted by interleave class, within a class into the gather's anchors and
        # the others (the two parts), each by block; the buckets of that counting sort (and of
        # the level-1 cells' sort by class, below); the list's segments.
        self.class_list = self._keep(ctx.buffer(reserve=4 * voxels))
        self.class_buckets = self._keep(ctx.buffer(reserve=4 * CLASS_PARTS * MAX_INTERLEAVE * max(n // CLASS_BLOCK, 1) ** 3 * CLASS_FACINGS))
        self.gather_anchors = self._keep(ctx.buffer(reserve=4 * voxels))  # lib/gather_anchors.glsl, per voxel
        # The classes of the voxels in each level-1 cell, and those cells sorted by class.
        self.cell_class_bits = self._keep(ctx.buffer(reserve=4 * sizes[1]))
        self.cells_by_class = self._keep(ctx.buffer(reserve=4 * sizes[1]))
        self.epoch = Epoch()  # a new grid: nothing was computed from its lists yet
        self.framebuffer = self._keep(ctx.empty_framebuffer((n, n)))

    def _keep(self, resource):
        self._resources.append(resource)
        return resource

    def _volume(self, mipmapped=False, views=1):
        """An n x n x (views n) RGBA16F volume of zeros (with a full mip chain if asked)."""
        n = self.n
        volume = self.ctx.texture3d((n, n, views * n), 4, data=bytes(TEXEL_BYTES * views * n ** 3), dtype=VOXEL_FORMAT)
        if mipmapped:
            volume.build_mipmaps()
        volume.filter = (self.ctx.LINEAR_MIPMAP_LINEAR if mipmapped else self.ctx.LINEAR, self.ctx.LINEAR)
        volume.repeat_x = volume.repeat_y = volume.repeat_z = False
        return self._keep(volume)

    @property
    def mip_count(self):
        return self.n.bit_length()  # N = 2^k has levels 0..k

    @property
    def voxel_size(self):
        return float(self.region.size) / self.n

    def bounds(self):
        """The region as a world box (lo, hi)."""
        lo = np.asarray(self.region.center, float) - self.region.size / 2.0
        return lo, lo + self.region.size

    def memory_bytes(self):
        return voxel_memory_bytes(self.n) if self.n else 0

    # -- binding ---------------------------------------------------------------------------

    def uniforms(self):
        return dict(voxel_region_min=tuple(self.bounds()[0]), voxel_region_size=float(self.region.size),
                    voxel_grid=self.n, voxel_size=self.voxel_size, voxel_max_mip=float(self.mip_count - 1),
                    voxel_emitters=self.emitting, voxel_sky=self.sky_lit)

    def bind_sums(self):
        """The voxelizer's sums and front-layer keys."""
        for channel, buffer in enumerate(self.sums):
            buffer.bind_to_storage_buffer(STORAGE_BINDING["VOXEL_SUMS"] + channel)
        self.front.bind_to_image(IMAGE_UNIT["FRONT"], read=True, write=True, format=GL_IMAGE_FORMAT["r32ui"])

    def use_surface(self):
        """The resolved surface volumes and the emitters' and the sky's light at them."""
        self.albedo.use(TEXTURE_UNIT["VOXEL_ALBEDO"])
        self.normal.use(TEXTURE_UNIT["VOXEL_NORMAL"])
        self.emission.use(TEXTURE_UNIT["VOXEL_EMISSION"])
        self.emitter_light.use(TEXTURE_UNIT["VOXEL_EMITTER_LIGHT"])
        self.sky_light.use(TEXTURE_UNIT["VOXEL_SKY_LIGHT"])

    def use_faces(self):
        """The face views and the emission volume: what cones read."""
        self.faces.use(TEXTURE_UNIT["VOXEL_FACES"])
        self.emitted.use(TEXTURE_UNIT["VOXEL_EMITTED"])

    def replace_covered(self):
        """Make `covered_next` (which a voxelization filled) the covered list, the old one the
        next to fill, and start a new epoch."""
        self.covered, self.covered_next = self.covered_next, self.covered
        self.covered.read_count()
        self.epoch = self.epoch.next()

    def bind_faces(self, level=0):
        bind_image(self.faces, IMAGE_UNIT["FACES_OUT"], level=level)

    def dispatch(self, handle, count):
        """Run a compute program once per entry of a voxel list (`count` entries), then make its
        writes visible to the texture fetches, image loads and buffer reads that follow."""
        if count:
            handle.program.run(math.ceil(count / LIST_GROUP))
        self.ctx.memory_barrier(self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.TEXTURE_FETCH_BARRIER_BIT
                                | self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.TEXTURE_UPDATE_BARRIER_BIT)

    # -- inspection --------------------------------------------------------------------------

    def read_level(self, volume, readback, level=0):
        """One mip level of a volume as float32 (depth, n, n, 4), indexed [z, y, x] (the
        face views' depth holds their six views one after the other)."""
        width, height, depth = (max(1, side >> level) for side in volume.size)
        shape = (depth, height, width, 4)
        if level == 0:
            return np.frombuffer(volume.read(), dtype="f2").reshape(shape).astype("f4")
        buffer = self.ctx.buffer(reserve=width * height * depth * 16)
        try:
            volume.use(TEXTURE_UNIT["VOXEL_INSPECT"])
            readback.set(level=level)
            buffer.bind_to_storage_buffer(STORAGE_BINDING["READBACK"])
            readback.program.run(*(math.ceil(side / VOLUME_GROUP) for side in (width, height, depth)))
            self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)
            return np.frombuffer(buffer.read(), dtype="f4").reshape(shape).copy()
        finally:
            buffer.release()

    def release(self):
        for resource in reversed(self._resources):
            resource.release()
        self._resources = []
        self.n = 0
        self.region = None


def bind_image(volume, unit, level=0, read=False):
    volume.bind_to_image(unit, read=read, write=True, level=level, format=GL_IMAGE_FORMAT["rgba16f"])


def _same_region(a, b):
    return float(a.size) == float(b.size) and np.array_equal(np.asarray(a.center, float), np.asarray(b.center, float))
