"""The voxel segments (engine/voxels/lists.py) that a work item of the radiance schedule runs
over, from its schedule.Voxels selection: the grid's touched, covered or cell lists, or an
interleave class of the class index (GatherPass.sort_classes)."""
from dataclasses import dataclass


@dataclass(frozen=True)
class GatherSegments:
    """What a gather runs over: the anchors to trace, the voxels to interpolate from them, and
    per level above the finest the segments holding the voxels beneath a finer level (the
    passes take their own among them)."""
    traced: object
    filled: object
    finer: dict


@dataclass(frozen=True)
class SkySegments(GatherSegments):
    """What the sky's light runs over: a gather's segments, and the voxels to filter."""
    filtered: object


def voxel_segment(grid, classes, voxels):
    """The VoxelSegment of a selection: the touched voxels, every voxel from the covered list
    (which a scroll keeps current without sorting the classes again), a class from the class
    index `classes`."""
    if voxels.kind == "touched":
        return grid.touched.segment()
    if voxels.kind == "every":
        return grid.covered.segment()
    return classes.segment(voxels.class_index)


def gather_segments(grid, classes, voxels):
    """The GatherSegments of a selection: a class's parts, or the touched voxels throughout."""
    if voxels.kind == "touched":
        touched = grid.touched.segment()
        return GatherSegments(touched, touched, _by_level(grid, touched))
    index = voxels.class_index
    return GatherSegments(classes.anchor_segment(index), classes.filled_segment(index), classes.finer_segments(index))


def sky_segments(grid, classes, voxels):
    """The SkySegments of a selection: for a class, its anchors, then every voxel (whose anchors
    may lie in any class: once the last class is traced every voxel holds what all the anchors
    brought), every class's voxels beneath a finer level and every covered voxel; or the
    touched voxels throughout."""
    if voxels.kind == "touched":
        touched = grid.touched.segment()
        return SkySegments(touched, touched, _by_level(grid, touched), touched)
    return SkySegments(classes.anchor_segment(voxels.class_index), classes.segment(), classes.finer_segments(),
                       grid.covered.segment())


def cell_segments(grid, classes, voxels):
    """The level-1 cells of a selection, as (VoxelSegment, the level of its entries): the
    covered cells, a class's cells, or the touched voxels themselves."""
    if voxels.kind == "touched":
        return [(grid.touched.segment(), 0)]
    if voxels.kind == "class":
        return [(segment, 1) for segment in classes.cell_segments(voxels.class_index)]
    return [(grid.cells.segment(1), 1)]  # every covered cell


def _by_level(grid, segment):
    """`segment` for each level above the finest, as GatherPass.fill takes the voxels beneath a
    finer level."""
    return {level: [segment] for level in range(1, grid.levels)}
