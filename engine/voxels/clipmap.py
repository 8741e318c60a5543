"""Where a frame's voxel levels lie: one grid over the scene's voxel region, or a clipmap's
levels centred on the camera (GL-free).

Level k of a clipmap is a cube of N^3 voxels 2^k v0 wide, its corner on a lattice of
level_snap_voxels(N) of its own voxels: a level moves in whole steps of that lattice as the
camera moves, and the cells of level k's mip 2 (4 of its voxels) fall on those of level k+1's
mip 1, so a cone passing from one level to the next reads the same cells at the same size."""
import numpy as np

from ..scene.model import Clipmap, VoxelRegion


def level_snap_voxels(resolution):
    """The voxels of a level's lattice step: an eighth of the level, so that a level scrolls as
    often whatever its resolution (each scroll sorts the classes and rebuilds the mips once,
    whatever the slab's size), and at least 4, the cells of its mip 2."""
    return max(4, resolution // 8)


def default_clipmap(levels, resolution, region):
    """`levels` levels of resolution^3 whose coarsest spans twice the scene's voxel region, so it
    reaches the far side of the scene from a camera anywhere inside it."""
    return Clipmap(levels, resolution, 2.0 * float(region.size) / (resolution * 2 ** (levels - 1)))


def level_regions(clipmap, eye):
    """The cube of each level, finest first, centred on `eye` as nearly as its lattice allows."""
    regions = []
    for level in range(clipmap.levels):
        voxel = clipmap.voxel_size * 2.0 ** level
        side = clipmap.resolution * voxel
        step = level_snap_voxels(clipmap.resolution) * voxel
        corner = np.floor((np.asarray(eye, float) - side / 2.0) / step + 0.5) * step
        regions.append(VoxelRegion(corner + side / 2.0, side))
    return tuple(regions)


def frame_levels(frame, settings, eye):
    """(N, the regions of the levels, finest first) of a frame: a clipmap of settings.clipmap_levels
    levels of settings.grid^3 over the scene (default_clipmap); where the setting is None, the
    scene's clipmap; else one grid of settings.grid^3 over the scene's voxel region."""
    if settings.clipmap_levels:
        clipmap = default_clipmap(settings.clipmap_levels, settings.grid, frame.region)
    elif settings.clipmap_levels is None and frame.clipmap is not None:
        clipmap = frame.clipmap
    else:
        return settings.grid, (frame.region,)
    return clipmap.resolution, level_regions(clipmap, eye)


def same_region(a, b):
    """Whether two cubes are the same, to the bit."""
    return float(a.size) == float(b.size) and np.array_equal(np.asarray(a.center, float), np.asarray(b.center, float))


def moved_levels(held, regions):
    """The levels whose cube differs between two placements of the same levels."""
    return frozenset(level for level, (a, b) in enumerate(zip(held, regions)) if not same_region(a, b))


def level_shift(held, region, n):
    """How many of its voxels a level of n^3 moved by between two placements, (x, y, z): its
    voxels' coordinates in the new cube are those in the old less the shift. None where it
    cannot scroll: another size, or a move by a whole cube or more (no voxel stays)."""
    if float(held.size) != float(region.size):
        return None
    voxel = float(region.size) / n
    shift = np.rint((np.asarray(region.center, float) - np.asarray(held.center, float)) / voxel).astype(int)
    if np.any(np.abs(shift) >= n):
        return None
    return tuple(int(step) for step in shift)


def scrolled_regions(held, target):
    """The placement a grid whose levels lie at `held` takes on its way to `target`: the finest
    level that moved goes to its place, the others wait for later frames. A frame voxelizes at
    most one level anew, as Wicked Engine's clipmaps do."""
    moved = moved_levels(held, target)
    if not moved:
        return tuple(held)
    finest = min(moved)
    return tuple(target[level] if level == finest else region for level, region in enumerate(held))


def with_coarser_levels(levels, count):
    """`levels` and the next coarser level of each, of `count` levels: a level's voxels beneath
    the finer level take their gather and sky light from it (gather/take_finer_gather.comp),
    and which of them lie beneath it changes where the finer level moves."""
    return frozenset(levels) | frozenset(level + 1 for level in levels if level + 1 < count)


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
