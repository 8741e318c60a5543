"""The voxel grid: L levels of N^3 voxels, each over a cube of the scene (one level over the
scene's voxel region, or a clipmap's nested cubes, level k's voxels 2^k times the finest), and
what they hold, owned by the renderer and passed to the passes that read and write it. The
levels are stacked along z in voxel space (glsl/lib/voxel.glsl): voxel (x, y, z) of level k is
(x, y, z + k N) of an N x N x LN stack, which the records, lists and cells address alike, and
each volume below stacks its levels along z the same way. Its owner keeps these invariants:
every volume starts zero and every empty voxel stays zero (passes touch only listed voxels);
a voxel holds a record exactly while some surface covers it, and a record's values start zero;
the covered list holds the voxel of each record (the voxels some surface covers), and its state
is an `Epoch`, a new one after each voxelization (`covered_changed`).

Per covered voxel, arrays of RGBA16F values indexed by the voxel's record (`records`,
engine/voxels/records.py; an empty voxel reads zero):
- the resolved surface of each voxel: `albedo`, mean `normal`, `emission` (a: the surface
  offset);
- the arrays the passes that write them own (records.RecordArrays, made zero for each
  records store): the light arriving at each voxel's surface (the emitters' and the sky's,
  EmitterLightPass and SkyLightPass), the radiance (`base`, InjectPass), the diffuse light
  each voxel gathered (GatherPass) and the light its surface reflected in the last
  composition, what cones read at level 0 (`reflected`, FaceViewsPass). A record handed out
  reads zero in each of them (`zero_new_records`, after a voxelization).

Volumes (RGBA16F with their mip chains, what cones read from mip level 1 up, where cells hold
several voxels: level 0 is the voxels' own records, their reflected light and mean normal):
the six one-sided face views, stacked along z in one volume ((n/2) x (n/2) x 6L(n/2) at mip
level 1, view f at z in [f L n/2, (f + 1) L n/2); FaceViewsPass holds and writes it), and,
where surfaces emit, `cone_emission` (emission, a: coverage; the voxelizer writes it): the emission
the specular cones see ((n/2) x (n/2) x L(n/2) and coarser: the cones that read it are at
least 4 voxels wide). engine/voxels/inspection.py reads
them back, and an array as a volume made from it.

Lists (lists.py): `covered` (the voxel of each record handed out, or NO_VOXEL at a free
one: lib/covered_voxels.glsl), `touched` (by the last voxelization), `newly_covered` (the
voxels it covered that were empty) and the covered `cells` of every mip level. The voxel lists have room for `list_room` covered
voxels (the touched list twice that: the voxels covered before and after an update):
NEW_GRID_ROOM n^2 per level in a new grid, or LIST_HEADROOM of what a voxelization needed when it last
grew. A voxelization that needs more room makes the grid anew with more (`list_counts`,
`grow_lists`). Scratch storage of one pass (the voxelizer's sums, the gather's anchors and
class lists) belongs to that pass.
"""
from dataclasses import dataclass

import moderngl
import numpy as np

from ..core.constants import (GL_IMAGE_FORMAT, GRID_SIZES, LIST_GROUP, MAX_VOXEL_LEVELS, VOXEL_FACES, VOXEL_FORMAT,
                              VOXEL_MEMORY_BUDGET, VOXEL_PACK_BITS, VOXEL_SIDES, VOXEL_SUM_CHANNELS)
from ..core.errors import VctError
from ..gpu.bindings import Image
from .lists import SEGMENT, CellLists, Epoch, VoxelList
from .records import VALUE_BYTES, VoxelRecords
from .room import ListBound

TEXEL_BYTES = 8  # RGBA16F
MIP_CHAIN = 8 / 7  # a full mip chain adds a seventh
# The list room of a new grid, per n^2 of each level: a closed box or Sponza covers 6.4-6.7 n^2 voxels,
# and the room left over takes the bound of a moved object's voxels (engine/voxels/room.py), so
# that moving one reads nothing back.
NEW_GRID_ROOM = 16
LIST_HEADROOM = 5 / 4  # a grown list's room over what it needed
# The voxels of the touched list the voxelizer's sums hold at once (a chunk), per n^2: a full
# voxelization of a closed box (6.5 n^2) is one chunk.
SUM_ROOM = 8
# The arrays of values a grid and its passes may hold per record (see the module's docstring).
RECORD_ARRAYS = ("albedo", "normal", "emission", "base", "gathered", "gathered_previous", "reflected",
                 "emitter_irradiance", "sky_irradiance", "traced_sky_irradiance")


def voxel_memory_bytes(n, levels=1):
    """GPU bytes a grid of `levels` levels of n^3 may need, the passes' storage sized by it included: the
    voxelizer's sums of a chunk and the touched voxels' records, the records (with the emitters' and the
    sky's light, as a scene may have), the volumes (faces and cone emission with their mips, an
    inspection volume) and the lists."""
    voxels = levels * n ** 3
    per_voxel = 4                                            # the records' index
    volumes = TEXEL_BYTES * (VOXEL_FACES / 8 + 1 + 1 / 8) * MIP_CHAIN  # faces, an inspection volume, cone emission
    lists = 2 * 4 / 7 + 2 * 4 / 8                            # cells, stamps; level-1 cells' classes, cells by class
    room = new_grid_room(n, levels)
    listed = 4 * 9 * room                                     # touched x2 and their records x2, covered x2, stale, classes, anchors
    records = (VALUE_BYTES * VOXEL_SIDES * len(RECORD_ARRAYS) + 4) * room   # the arrays and the pool
    sums = 4 * (VOXEL_SIDES * len(VOXEL_SUM_CHANNELS) + VOXEL_FACES) * sum_room(n, levels)  # and the front-layer keys
    return int(voxels * (per_voxel + volumes + lists) + listed + records + sums)


def new_grid_room(n, levels):
    """The list room of a new grid of `levels` levels of n^3 (VoxelGrid.list_room)."""
    return levels * min(NEW_GRID_ROOM * n * n, n ** 3)


def sum_room(n, levels):
    """The voxels of the touched list the voxelizer's sums of a grid of `levels` levels of n^3
    hold at once: surfaces cover n^2 voxels of each level."""
    return levels * min(SUM_ROOM * n * n, n ** 3)


def list_room(needed, n, levels):
    """Room for `needed` covered voxels of a grid of `levels` levels of n^3 and LIST_HEADROOM
    more, in whole dispatch groups, at most every voxel."""
    return min(-(-int(needed * LIST_HEADROOM) // LIST_GROUP) * LIST_GROUP, levels * n ** 3)


def check_grid(ctx, n, levels=1, source=None, field="grid"):
    """Refuse a grid of `levels` levels of n^3 before anything is allocated (VctError naming
    `field`)."""
    name = f"grid {n}" + (f" x {levels} levels" if levels > 1 else "")
    if n not in GRID_SIZES:
        raise VctError(f"grid must be a power of two from {GRID_SIZES[0]} to {GRID_SIZES[-1]}, got {n}", source=source, field=field)
    max_size = ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", 2048)
    depth = VOXEL_FACES * levels * n // 2  # the face views' level 1, stacked along z
    if max(n, depth) > max_size:
        raise VctError(f"{name} needs 3D textures {max(n, depth)} texels deep, over the driver's "
                       f"GL_MAX_3D_TEXTURE_SIZE {max_size}", source=source, field=field)
    need = voxel_memory_bytes(n, levels)
    if need > VOXEL_MEMORY_BUDGET:
        raise VctError(f"{name} needs {need / 2**30:.1f} GiB of voxel memory, over the budget of "
                       f"{VOXEL_MEMORY_BUDGET / 2**30:.1f} GiB", source=source, field=field)


class Placement:
    """Where L levels of n^3 voxels lie: `n` and `regions` (a VoxelRegion per level, finest
    first) and what follows from them."""

    @property
    def levels(self):
        return len(self.regions)

    @property
    def voxel_count(self):
        """The voxels of every level."""
        return self.levels * self.n ** 3

    @property
    def mip_count(self):
        return self.n.bit_length()  # N = 2^k has levels 0..k

    @property
    def voxel_size(self):
        """The finest level's voxel size."""
        return self.level_voxel_size(0)

    def level_voxel_size(self, level):
        return float(self.regions[level].size) / self.n

    def level_bounds(self, level):
        """A level's cube as a world box (lo, hi)."""
        region = self.regions[level]
        lo = np.asarray(region.center, float) - region.size / 2.0
        return lo, lo + region.size

    def bounds(self):
        """The box of every level's cube (lo, hi)."""
        boxes = [self.level_bounds(level) for level in range(self.levels)]
        return np.min([lo for lo, _ in boxes], axis=0), np.max([hi for _, hi in boxes], axis=0)


@dataclass(frozen=True)
class VoxelLayout(Placement):
    """A grid's placement at one frame, and the room of its lists (Renderer.voxel_layout)."""
    n: int
    regions: tuple
    list_room: int


class VoxelGrid(Placement):
    # What a program reading the voxels' surface (glsl/lib/voxel_surface.glsl) declares.
    SURFACE_READS = ("SSBO_VOXEL_RECORD", "SSBO_VOXEL_ALBEDO", "SSBO_VOXEL_NORMAL", "SSBO_VOXEL_EMISSION")
    # What a program tracing cones (glsl/lib/cone.glsl) declares besides the emission volume:
    # level 0 is the voxels' records.
    CONE_READS = (*SURFACE_READS, "SSBO_VOXEL_REFLECTED", "TEX_VOXEL_FACES")

    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.n = 0
        self.regions = ()  # a VoxelRegion per level, finest first
        self._uniforms = None
        self.list_room = 0
        self._resources = []
        self.epoch = Epoch()  # of the covered list: a new one whenever it changes (covered_changed)
        self.size_program = programs.compute("voxel_grid/size_segment.comp", reads=("SSBO_COUNTED",), writes=("SSBO_SEGMENTS",))
        self.size_cells_program = programs.compute("voxel_grid/size_cell_segments.comp", reads=("SSBO_COUNTED",),
                                                   writes=("SSBO_SEGMENTS",))
        self.zero_program = programs.compute("voxel_grid/zero_new_records.comp", reads=("SSBO_NEWLY_COVERED", "SSBO_VOXEL_RECORD"),
                                             writes=("SSBO_VOXEL_BASE", "SSBO_VOXEL_GATHERED", "SSBO_GATHERED_OUT",
                                                     "SSBO_VOXEL_REFLECTED", "SSBO_VOXEL_EMITTER_IRRADIANCE",
                                                     "SSBO_VOXEL_SKY_IRRADIANCE", "SSBO_VOXEL_TRACED_SKY_IRRADIANCE"))

    # -- allocation ----------------------------------------------------------------------

    def ensure(self, n, regions, source=None, field="grid"):
        """Hold a grid of n^3 voxels per level over `regions` (a cube per level, finest first):
        an empty one where it holds another size or level count, the same one moved where only
        the regions differ (the levels that moved are to be voxelized anew). True when made."""
        regions = tuple(regions)
        if n == self.n and len(regions) == self.levels:
            self.regions = regions
            return False
        levels = len(regions)
        check_grid(self.ctx, n, levels, source, field)
        room = new_grid_room(n, levels)
        if self.n:  # the room the last grid grew to, scaled to the new size: surfaces cover n^2
            room = min(max(room, self.list_room * n * n * levels // (self.n * self.n * self.levels)), levels * n ** 3)
        self._release_resources()
        self.regions = regions
        self._allocate(n, room)
        return True

    def list_counts(self):
        """After a voxelization: its covered and touched counts as a ListBound, read back from
        the GPU (its `needed()` the list room they take), and the records the pool was short."""
        held, short = self.records.read_counts()
        return ListBound(covered=held, touched=self.touched.read_count(), records_short=short)

    def grow_lists(self, needed):
        """Make the grid anew, empty, with list room for `needed` covered voxels (list_room),
        holding a cone emission volume if it held one (the voxelization that follows fills it;
        the passes' arrays are made again for its records)."""
        emits = self.cone_emission is not None
        self._release_resources()
        self._allocate(self.n, list_room(needed, self.n, self.levels))
        self.hold_cone_emission(emits)

    def _allocate(self, n, room):
        ctx = self.ctx
        self.n, self.list_room = n, room
        self._mipmapped = set()  # the volumes whose mip chain is allocated
        self.records = self._keep(VoxelRecords(ctx, n, self.levels, room))
        self.albedo, self.normal, self.emission = (self._values() for _ in range(3))
        self.cone_emission = None  # hold_cone_emission
        self.touched = self._keep(VoxelList(ctx, self.touched_room))
        self.covered, self.newly_covered = (self._keep(VoxelList(ctx, room)) for _ in range(2))
        self.covered.clear()  # no record handed out yet
        self.cells = self._keep(CellLists(ctx, n, self.levels))
        self.epoch = Epoch()  # a new grid: nothing was computed from its lists yet

    def load(self, albedo, normal, emission=None):
        """Hold surfaces given per voxel instead of voxelized ones: float arrays (L n, n, n, 3)
        indexed [z, y, x] (the levels stacked along z) of reflectance, mean normal (a voxel is covered where it is nonzero;
        its length is the normals' coherence) and emission, each surface through its voxel's
        centre. The covered list and cells follow (a new epoch); the radiance volumes are
        zero. For grids made by hand, such as the tests of single passes."""
        n, depth = self.n, self.levels * self.n
        if not n:
            raise VctError("no grid to load: ensure(n, regions) makes one first", field="VoxelGrid.load")
        for name, array in (("albedo", albedo), ("normal", normal), ("emission", emission)):
            if array is not None and np.shape(array) != (depth, n, n, 3):
                raise VctError(f"must be an array of shape ({depth}, {n}, {n}, 3), got {np.shape(array)}", field=name)
        normal = np.asarray(normal, np.float32)
        covered = np.any(normal != 0.0, axis=-1)
        emission = np.zeros_like(normal) if emission is None else np.asarray(emission, np.float32)
        self._release_resources()
        self._allocate(n, max(new_grid_room(n, self.levels), list_room(np.count_nonzero(covered), n, self.levels)))
        flag = covered[..., None].astype(np.float32)
        z, y, x = np.nonzero(covered)
        coords = np.stack([x, y, z], axis=-1)
        self.records.hold(coords)
        self.hold_cone_emission(np.any(emission != 0.0))
        for array, rgb, a in ((self.albedo, albedo, flag), (self.normal, normal, flag), (self.emission, emission, 0.0 * flag)):
            values = np.zeros((len(z), VOXEL_SIDES, 4), np.float32)  # each surface its voxel's side 0
            values[:, 0] = np.concatenate([np.asarray(rgb, np.float32), a], axis=-1)[z, y, x]
            array.write(values.astype(VOXEL_FORMAT).tobytes())
        if self.cone_emission is not None:  # its level 1: the mean of each cell's 8 voxels
            level_one = np.concatenate([emission * flag, flag], axis=-1).reshape(depth // 2, 2, n // 2, 2, n // 2, 2, 4).mean(axis=(1, 3, 5))
            self.cone_emission.write(level_one.astype(VOXEL_FORMAT).tobytes())
        self.covered.buffer.write(np.concatenate([[len(coords)], pack_voxels(coords)]).astype("u4").tobytes())
        self.covered.table.write(0, 1, len(coords))
        for level in range(1, self.mip_count):
            cells = np.unique(coords >> level, axis=0)
            first = self.cells.entries_first(level)
            self.cells.buffer.write(pack_voxels(cells).astype("u4").tobytes(), offset=4 * first)
            self.cells.buffer.write(np.array([len(cells)], "u4").tobytes(), offset=4 * level)
            self.cells.table.write(level, first, len(cells))

    def write_values(self, values, volume):
        """Set an array of values from a volume given per voxel: float (L n, n, n, 4) indexed
        [z, y, x], taken at the covered voxels (for grids made by hand, as `load`)."""
        n, depth = self.n, self.levels * self.n
        if np.shape(volume) != (depth, n, n, 4):
            raise VctError(f"must be an array of shape ({depth}, {n}, {n}, 4), got {np.shape(volume)}", field="volume")
        index = np.frombuffer(self.records.index.read(), "u4").reshape(depth, n, n)
        held = index > 0
        data = np.zeros((self.records.room, VOXEL_SIDES, 4), VOXEL_FORMAT)  # side 0, as `load` holds the surfaces
        data[index[held] - 1, 0] = np.asarray(volume, np.float32)[held]
        values.write(data.tobytes())

    def hold_cone_emission(self, emits):
        """Hold the emission volume the specular cones read where surfaces emit (`emits`), and
        none where none does. True when made now: zero, its covered cells still to fill
        (VoxelizePass.fill_cone_emission)."""
        if emits and self.cone_emission is None:
            self.cone_emission = self._volume(mipmapped=True, side=self.n // 2)  # its mip level 1
            return True
        if not emits and self.cone_emission is not None:
            self._drop(self.cone_emission)
            self.cone_emission = None
        return False

    def viewable(self, volume):
        """`volume` with its hardware mip chain built (build_mips), counted in memory_bytes."""
        self._mipmapped.add(build_mips(volume))
        return volume

    def _keep(self, resource):
        self._resources.append(resource)
        return resource

    def _drop(self, resource):
        self._resources.remove(resource)
        self._mipmapped.discard(resource)
        resource.release()

    def _values(self):
        """An array of values per record, zero."""
        return self._keep(self.records.array())

    def _volume(self, mipmapped=False, slabs=1, side=None):
        """A volume of zeros of the grid's stacked levels (zero_volume), kept with its resources."""
        volume = zero_volume(self.ctx, side or self.n, slabs * self.levels)
        if mipmapped:
            self.viewable(volume)
        return self._keep(volume)

    @property
    def touched_room(self):
        """The touched list's room: the voxels covered before and after an update."""
        return min(2 * self.list_room, self.voxel_count)

    def level_mask(self, levels=None):
        """Levels as a bit mask (bit k: level k) for the shaders; None: every level."""
        return sum(1 << level for level in (range(self.levels) if levels is None else levels))

    def layout(self):
        """Its placement now, as a VoxelLayout."""
        return VoxelLayout(self.n, self.regions, self.list_room)

    def memory_bytes(self):
        """GPU bytes the grid holds now: its volumes (their mip chains where allocated) and lists."""
        return sum(gpu_bytes(resource, resource in self._mipmapped) for resource in self._resources)

    # -- binding ---------------------------------------------------------------------------

    def uniforms(self):
        """The uniforms of glsl/lib/voxel.glsl (made again when the grid or its levels move)."""
        if self._uniforms is None or self._uniforms[0] is not self.regions or self._uniforms[1]["voxel_grid"] != self.n:
            corners = np.zeros((MAX_VOXEL_LEVELS, 3), "f4")
            sizes = np.zeros(MAX_VOXEL_LEVELS, "f4")
            for level in range(self.levels):
                corners[level], sizes[level] = self.level_bounds(level)[0], self.level_voxel_size(level)
            self._uniforms = (self.regions, dict(voxel_grid=self.n, voxel_levels=self.levels, level_region_min=corners.tobytes(),
                                        level_voxel_size=sizes.tobytes(), voxel_size=self.voxel_size,
                                        voxel_max_mip=float(self.mip_count - 1)))
        return self._uniforms[1]

    def surface(self):
        """What a program reading the voxels' surface binds (SURFACE_READS: their records and
        resolved surface)."""
        return dict(zip(self.SURFACE_READS, (self.records.index, self.albedo, self.normal, self.emission)))

    def covered_changed(self, scrolled_levels=None):
        """After a voxelization wrote the covered list: its segment row from its count, and a
        new epoch (`scrolled_levels`: Epoch.scrolled_levels)."""
        self.size_list(self.covered)
        self.epoch = self.epoch.next(scrolled_levels)

    def dispatch(self, handle, segment, **resources):
        """Run a compute program once per entry of a list segment (a VoxelSegment: its table
        bound as SSBO_SEGMENTS where the program reads it and its row as the program's
        `segment`, the dispatch's size read by the GPU from the row) with its other `resources`
        (ProgramHandle.bind), then make its writes visible to the texture fetches, image
        loads, buffer reads and indirect dispatches that follow."""
        if "SSBO_SEGMENTS" in handle.reads:  # not where the program reads its list's count from the list
            resources["SSBO_SEGMENTS"] = segment.table.buffer
        handle.set(segment=segment.row)
        handle.run_indirect(segment.table.buffer, SEGMENT.itemsize * segment.row, **resources)
        self.barrier()

    def zero_new_records(self, base, gathered, reflected, emitter_irradiance=None, sky_irradiance=None,
                         traced_sky_irradiance=None):
        """After a voxelization, the values at the records it handed out (its newly covered
        voxels) zero in the passes' arrays of them (records.RecordArrays; the emitters' and the
        sky's light where the scene has them): those records were other voxels' before."""
        self.zero_program.set(**self.uniforms(), voxel_emitters=emitter_irradiance is not None,
                              voxel_sky=sky_irradiance is not None)
        self.dispatch(self.zero_program, self.newly_covered.segment(), SSBO_NEWLY_COVERED=self.newly_covered.buffer,
                      SSBO_VOXEL_RECORD=self.records.index, SSBO_VOXEL_BASE=base, SSBO_VOXEL_GATHERED=gathered[0],
                      SSBO_GATHERED_OUT=gathered[1], SSBO_VOXEL_REFLECTED=reflected,
                      SSBO_VOXEL_EMITTER_IRRADIANCE=emitter_irradiance, SSBO_VOXEL_SKY_IRRADIANCE=sky_irradiance,
                      SSBO_VOXEL_TRACED_SKY_IRRADIANCE=traced_sky_irradiance)

    def size_list(self, voxel_list):
        """The segment row of a voxel list (every entry) from its count, after a pass appended."""
        self.size_program.run(1, SSBO_COUNTED=voxel_list.buffer, SSBO_SEGMENTS=voxel_list.table.buffer)
        self.barrier()

    def size_cells(self):
        """The segment rows of every level's covered cells from their counts, after they are
        listed."""
        self.size_cells_program.set(top_level=self.mip_count - 1, level_first=self.cells.first_words())
        self.size_cells_program.run(1, SSBO_COUNTED=self.cells.buffer, SSBO_SEGMENTS=self.cells.table.buffer)
        self.barrier()

    def barrier(self):
        """Make a pass's writes visible to what follows, indirect dispatches included."""
        self.ctx.memory_barrier(self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.TEXTURE_FETCH_BARRIER_BIT
                                | self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.TEXTURE_UPDATE_BARRIER_BIT
                                | self.ctx.COMMAND_BARRIER_BIT)

    def _release_resources(self):
        for resource in reversed(self._resources):
            resource.release()
        self._resources = []

    def release(self):
        self._release_resources()
        self.n = 0
        self.regions = ()
        for handle in (self.size_program, self.size_cells_program, self.zero_program):
            handle.release()


def gpu_bytes(resource, mipmapped=False):
    """GPU bytes of a buffer, a texture (and its mip chain), or an object holding some."""
    if hasattr(resource, "memory_bytes"):
        return resource.memory_bytes()
    if isinstance(resource, moderngl.Buffer):
        return resource.size
    if isinstance(resource, (moderngl.Texture, moderngl.Texture3D)):
        texel = resource.components * np.dtype(resource.dtype).itemsize
        return int(np.prod(resource.size) * texel * (MIP_CHAIN if mipmapped else 1))
    return 0  # a framebuffer without attachments


class GridStorage:
    """The GPU resources a pass keeps for grids of one kind (a size n^3, or a size and list
    room): released when the kind changes, before the pass makes them again for the new one."""

    def __init__(self):
        self.kind, self.resources = None, []

    def holds(self, kind):
        return kind == self.kind

    def hold(self, kind, resources):
        self.kind, self.resources = kind, list(resources)

    def memory_bytes(self):
        return sum(gpu_bytes(resource) for resource in self.resources)

    def release(self):
        for resource in self.resources:
            resource.release()
        self.kind, self.resources = None, []


def pack_voxels(coords):
    """Voxel coordinates (k, 3) as x, y, z packed into one uint each (lib/voxel.glsl pack_voxel)."""
    coords = np.asarray(coords, np.uint32).reshape(-1, 3)
    return coords[:, 0] | (coords[:, 1] << VOXEL_PACK_BITS) | (coords[:, 2] << (2 * VOXEL_PACK_BITS))


def unpack_voxels(entries):
    """Packed voxel coordinates (pack_voxels) as (k, 3) x, y, z."""
    entries = np.asarray(entries, np.uint32)
    mask = (1 << VOXEL_PACK_BITS) - 1
    return np.stack([entries & mask, (entries >> VOXEL_PACK_BITS) & mask, entries >> (2 * VOXEL_PACK_BITS)], axis=-1)


def zero_volume(ctx, side, stacks):
    """A side x side x (stacks side) RGBA16F volume of zeros: `stacks` stacks of side^3 along z,
    filtered linearly and clamped."""
    depth = stacks * side
    volume = ctx.texture3d((side, side, depth), 4, data=bytes(TEXEL_BYTES * side * side * depth), dtype=VOXEL_FORMAT)
    volume.filter = (ctx.LINEAR, ctx.LINEAR)
    volume.repeat_x = volume.repeat_y = volume.repeat_z = False
    return volume


def build_mips(volume):
    """`volume` with its hardware mip chain built, sampled trilinearly through it."""
    volume.build_mipmaps()
    volume.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    return volume


def volume_image(volume, level=0, read=False):
    """A level of an RGBA16F volume as an image unit binds it, to write (and read, if `read`)."""
    return Image(volume, level, read=read, write=True, format=GL_IMAGE_FORMAT["rgba16f"])
