"""What a frame is made from, read off the scene itself, and what changed since a stage of the
frame last ran. GL-free: the renderer decides from this which passes a frame needs.

Mesh arrays are read-only, so a mesh is unchanged while it holds the same array objects;
transforms, materials and lights are compared by value.
"""
from dataclasses import dataclass, field

import numpy as np

from .emitters import is_emissive


def material_values(material):
    """Everything about a material the passes read, as a comparable tuple (textures compare
    by identity)."""
    return (tuple(float(x) for x in material.albedo), float(material.roughness), float(material.metalness),
            float(material.specular), tuple(float(x) for x in material.emission), float(material.alpha),
            material.alpha_mode, float(material.alpha_cutoff), bool(material.double_sided),
            float(material.normal_scale), tuple(material.textures()), tuple(sorted(material.uv_sets.items())),
            tuple(sorted(material.uv_transforms.items())))


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


def cutout_values(material):
    """What of a material shadow maps see: its alpha cut-out, if it has one."""
    if material.alpha_mode == "OPAQUE":
        return None
    return (material.alpha_mode, float(material.alpha_cutoff), float(material.alpha), material.base_color_texture)


def light_values(light):
    """A world-space light as a comparable tuple."""
    return (light.type, tuple(light.position.tolist()), tuple(light.direction.tolist()),
            tuple(float(x) for x in light.intensity), float(light.range), float(light.inner_angle_deg),
            float(light.outer_angle_deg), bool(light.cast_shadows))


@dataclass(frozen=True, eq=False)
class Draw:
    """One mesh instance of a frame: its node, mesh, world matrix, material and world bounds."""

    key: tuple          # (id(node), occurrence): the same instance from frame to frame
    node: object
    mesh: object
    mesh_arrays: tuple  # the mesh's arrays this frame (scene.Mesh.arrays)
    world: np.ndarray
    material: object
    material_values: tuple
    bounds: tuple       # (lo, hi) in world space

    def same_geometry(self, other):
        return (self.mesh is other.mesh and all(a is b for a, b in zip(self.mesh_arrays, other.mesh_arrays))
                and np.array_equal(self.world, other.world))

    def same_caster(self, other):
        """The same as shadow maps see it: geometry and alpha cut-out."""
        return self.key == other.key and self.same_geometry(other) and \
            cutout_values(self.material) == cutout_values(other.material)

    def __eq__(self, other):
        return (isinstance(other, Draw) and self.key == other.key and self.same_geometry(other)
                and self.material_values == other.material_values)

    __hash__ = None


class FrameInputs:
    """A snapshot of the scene for one frame: draws, world-space lights, bounds, voxel region or clipmap."""

    def __init__(self, scene, bounds_cache):
        self.draws = []
        seen = {}
        for node, world in scene.drawables():
            occurrence = seen[id(node)] = seen.get(id(node), -1) + 1
            world = np.array(world, dtype=np.float64)
            world.flags.writeable = False
            self.draws.append(Draw((id(node), occurrence), node, node.mesh, node.mesh.arrays(), world, node.material,
                                   material_values(node.material), bounds_cache.bounds(node.mesh, world)))
        bounds_cache.keep_only(self.draws)
        self.lights = [light for _, light in scene.lights()]
        self.light_values = tuple(light_values(light) for light in self.lights)
        self.environment = scene.environment
        self.environment_values = environment_values(scene.environment)
        if self.draws:
            self.bounds = (np.min([d.bounds[0] for d in self.draws], axis=0), np.max([d.bounds[1] for d in self.draws], axis=0))
        else:
            self.bounds = (np.zeros(3), np.zeros(3))
        self.region = scene.region(self.bounds)
        self.clipmap = scene.clipmap

    def emissive_draws(self):
        """The draws whose material emits light."""
        return tuple(d for d in self.draws if is_emissive(d.material))

    def casters(self):
        """What shadow maps depend on besides the lights: every draw's mesh, transform and cut-out."""
        return Casters(self.draws)


class Casters:
    """The draws as shadow maps see them, compared draw by draw (Draw.same_caster)."""

    def __init__(self, draws):
        self.draws = draws

    def __eq__(self, other):
        return isinstance(other, Casters) and len(self.draws) == len(other.draws) and \
            all(a.same_caster(b) for a, b in zip(self.draws, other.draws))

    def changed_bounds(self, other):
        """World boxes (lo, hi) of the draws that differ from `other`'s as shadow maps see
        them, as they were and as they are: a shadow view none of them reaches is unchanged."""
        removed, added = changed_draws(other.draws, self.draws, Draw.same_caster)
        return [d.bounds for d in removed + added]

    __hash__ = None


class BoundsCache:
    """World bounds per (mesh, transform), computed once: transforming every vertex each frame
    would cost more than a whole frame on large meshes."""

    def __init__(self):
        self._bounds = {}

    def bounds(self, mesh, world):
        key = (id(mesh.positions), world.tobytes())
        entry = self._bounds.get(key)
        if entry is None or entry[0] is not mesh.positions:
            entry = (mesh.positions, *mesh.bounds(world))
            self._bounds[key] = entry
        return entry[1], entry[2]

    def keep_only(self, draws):
        live = {(id(d.mesh_arrays[0]), d.world.tobytes()) for d in draws}
        for key in [k for k in self._bounds if k not in live]:
            del self._bounds[key]


@dataclass
class VoxelUpdate:
    """The draws to take out of the grid (as they were) and to put in (as they are). `full`:
    rebuild every voxel from `added` (all current draws). `levels`: the levels (moved with the
    camera) whose every voxel is rebuilt from all the draws. `scrolled`: the levels that moved
    by part of their cube, each with its shift (x, y, z, in its own voxels): their voxels move
    with their records and only the slabs they took in are voxelized."""

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


def changed_draws(previous, current, same):
    """(removed, added): the draws of `previous` that `current` holds no longer or holds
    otherwise, and the draws of `current` new or changed, matched by key and compared by
    `same(a, b)`."""
    before = {d.key: d for d in previous}
    after = {d.key: d for d in current}
    removed = [d for key, d in before.items() if key not in after or not same(after[key], d)]
    added = [d for key, d in after.items() if key not in before or not same(before[key], d)]
    return removed, added


def voxel_update(previous, current, levels=frozenset(), scrolled=None):
    """The update from the draws a grid holds (`previous`, None for an empty grid) to `current`,
    with the grid's `levels` moved and rebuilt, and those of `scrolled` ({level: shift}) scrolled."""
    if previous is None:
        return VoxelUpdate(True, [], list(current))
    return VoxelUpdate(False, *changed_draws(previous, current, Draw.__eq__), frozenset(levels), dict(scrolled or {}))


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
