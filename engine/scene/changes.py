"""What a frame is made from, read off the scene table (engine/scene/table.py), and what
changed since a stage of the frame last ran. GL-free: the renderer decides from this which
passes a frame needs."""
from dataclasses import dataclass, field

import numpy as np


class _Same:
    """A value compared by identity: a read-only array, which an edit replaces."""

    def __init__(self, value):
        self.value = value

    def __eq__(self, other):
        return isinstance(other, _Same) and other.value is self.value

    __hash__ = None


def environment_values(environment):
    """What of an environment the passes read, as a comparable tuple (the image by identity);
    None without one."""
    if environment is None:
        return None
    return (tuple(float(x) for x in environment.radiance), _Same(environment.image), float(environment.scale),
            float(environment.rotation_y_deg))


class FrameInputs:
    """What one frame is made from besides the scene table: the lights, the scene's bounds, its
    voxel region or clipmap and its environment."""

    def __init__(self, scene, table):
        self.table = table
        self.lights, self.light_values = table.lights, table.light_values
        self.environment = scene.environment
        self.environment_values = environment_values(scene.environment)
        self.bounds = table.bounds
        self.region = scene.region(self.bounds)
        self.clipmap = scene.clipmap

    def emissive_draws(self):
        """The draws whose material emits light, as the table's DrawViews."""
        return [self.table.draw(index) for index in self.table.emissive_draws()]


@dataclass(frozen=True, eq=False)
class PlacedDraw:
    """A draw where the voxels hold it or where it is now: its index in the table, its world
    matrix, the mesh arrays it had, its world bounds (lo, hi), its mesh's place in the GPU's
    pool (scene_buffers.MeshEntry) and whether it is posed (its copy in the pool holds only
    its latest pose: where the voxels hold it is known by its bounds)."""
    index: int
    world: np.ndarray
    mesh_arrays: tuple
    bounds: tuple
    entry: object
    posed: bool = False


class HeldDraws:
    """The draws as the voxel grid holds them: what each was at the last voxelization, for the
    next one to take out where it has moved (engine/passes/voxelize.py marks the voxels a held
    draw covered). Valid for one table structure and one packing of the mesh pool."""

    def __init__(self):
        self.key = None
        self.draws = []

    def holds(self, key):
        """Whether it holds the draws of (table structure, pool epoch) `key`."""
        return key == self.key

    def placed(self, table, buffers, indices):
        """PlacedDraws of `indices` as they are now."""
        return [PlacedDraw(int(i), table.draw_world[i].copy(), table.mesh_arrays[table.draw_mesh[i]],
                           (table.draw_bounds[i, 0].copy(), table.draw_bounds[i, 1].copy()), buffers.draw_entries[i],
                           int(i) in table.poses)
                for i in indices]

    def held(self, indices):
        return [self.draws[i] for i in indices]

    def hold(self, key, table, buffers, indices=None):
        """Hold the draws of `indices` (None: all of them, for `key`) as they are now."""
        if indices is None:
            self.key = key
            self.draws = self.placed(table, buffers, range(table.draw_count))
            return
        for draw in self.placed(table, buffers, indices):
            self.draws[draw.index] = draw


@dataclass
class VoxelUpdate:
    """The draws (PlacedDraws) to take out of the grid (as they were) and to put in (as they
    are). `full`: rebuild every voxel from every draw (`added` holds none). `levels`: the levels
    (moved with the camera) whose every voxel is rebuilt from all the draws. `scrolled`: the
    levels that moved by part of their cube, each with its shift (x, y, z, in its own voxels):
    their voxels move with their records and only the slabs they took in are voxelized."""

    full: bool
    removed: list
    added: list
    levels: frozenset = frozenset()
    scrolled: dict = field(default_factory=dict)

    @property
    def draws_changed(self):
        return bool(self.full or self.removed or self.added)

    @property
    def scrolls_only(self):
        """Levels scrolled, and nothing else changed: the voxels they kept hold what they held."""
        return bool(self.scrolled) and not self.draws_changed and not self.levels

    def changed_levels(self, level_count):
        """The levels of a grid of `level_count` whose voxels the update changes: all of them
        where it rebuilds every voxel or draws changed (they may lie in any level), else the
        moved ones."""
        if self.draws_changed:
            return frozenset(range(level_count))
        return self.levels | frozenset(self.scrolled)

    def rebuilt_levels(self):
        """The levels whose every voxel is voxelized anew (after their scroll, for a scrolled
        level while draws change too: its slabs are not all that changed)."""
        return self.levels | (frozenset(self.scrolled) if self.draws_changed else frozenset())

    def relit_levels(self, level_count):
        """The levels whose voxels all take their light again: all of them where draws changed
        (what they occlude may lie anywhere), else the rebuilt ones. A scrolled level's voxels
        keep theirs: only those it took in (the touched voxels) take light."""
        return frozenset(range(level_count)) if self.draws_changed else self.levels

    def touched_bounds(self, margin):
        """World box holding every voxel the removed and added draws cover, grown by `margin`."""
        boxes = [d.bounds for d in self.removed + self.added]
        return np.min([b[0] for b in boxes], axis=0) - margin, np.max([b[1] for b in boxes], axis=0) + margin


class Stage:
    """What a stage of the frame last ran on, its inputs by name: it runs again when one of
    them differs (or always, when change tracking is off). `version` counts its runs, an input
    of the stages after it."""

    def __init__(self):
        self.inputs = None
        self.version = 0

    def changed(self, inputs, tracking=True):
        """The names of `inputs` ({name: value}) whose values differ from the last run's (each
        compared as a tuple compares its items); every name where it never ran or tracking is
        off. Empty: the stage need not run."""
        if not tracking or self.inputs is None:
            return frozenset(inputs)
        return frozenset(name for name, value in inputs.items()
                         if not (self.inputs[name] is value or self.inputs[name] == value))

    def last(self, name):
        """The value input `name` had at the last run (None before the first)."""
        return None if self.inputs is None else self.inputs[name]

    def ran(self, inputs):
        self.inputs = dict(inputs)
        self.version += 1

    def extended(self, inputs):
        """Ran on `inputs` over voxels a scroll took in, what it made elsewhere unchanged: the
        stages after it, which read its version, need not run again."""
        self.inputs = dict(inputs)

    def forget(self):
        self.inputs = None
