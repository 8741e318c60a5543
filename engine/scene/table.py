"""The scene as arrays, kept up to date from the scene model's edit log (engine.scene.model.EDITS)
instead of a walk of the scene each frame. GL-free: the renderer decides from it which passes a
frame needs, and the GPU copies of the scene (engine/gpu/scene_buffers.py) are written from its rows.

Rows: every node occurrence of the scene graph in depth-first order (a node reached twice has
two rows), each with its parent row, local and world matrices; a subtree is a contiguous run
of rows. Draws: the rows whose node has a mesh, each with the slots of its mesh and material
(each mesh and material once, however many nodes use it), its world matrix and world bounds.
Lights: the rows whose node carries a light, in world space.

A sync reads the objects edited since the last one: a node's new transform updates the world
matrices of its subtree (depth by depth, all rows of a depth at once), a material's or mesh's
edit the draws that use it, a light's the lights; an edit of the graph's shape (a node's
children, mesh, light or camera given or taken) or a scene the table does not hold builds it
anew. What changed is kept as stamps: `stamp` counts the syncs, and each draw carries the stamp
of the sync that last changed its geometry (mesh or world matrix), its surface (material) and
what shadow maps see of it (geometry or alpha cut-out). A stage of the frame keeps the stamp it
last ran at and asks for the draws changed since: a frame where nothing moved costs the same
whatever the scene holds.
"""
import collections
from dataclasses import dataclass, fields

import numpy as np

from ..core import transforms
from .emitters import is_emissive
from .model import EDITS, Light, Material, Mesh, Node

EXTREMES_HULL_VERTICES = 64  # meshes with more vertices are bounded through their convex hull's
RECENT_CHANGES = 1 << 16     # draws of the recent changes kept, to find what changed since a stamp


def _comparable(value):
    """A field's value as one that compares with ==: arrays and dicts as tuples (Textures
    compare by identity)."""
    if isinstance(value, np.ndarray):
        return tuple(value.ravel().tolist())
    if isinstance(value, dict):
        return tuple(sorted((key, _comparable(item)) for key, item in value.items()))
    return value


MATERIAL_VALUE_FIELDS = tuple(f.name for f in fields(Material) if f.name != "name")


def material_values(material):
    """Every field of a material but its name (all of them the passes read), as a comparable
    tuple: a field added to Material is compared with the others."""
    return tuple(_comparable(getattr(material, name)) for name in MATERIAL_VALUE_FIELDS)


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


def mesh_extremes(mesh):
    """The vertices of a mesh that bound it under any affine map: its convex hull's (all of
    them for a small or flat mesh), so a draw's world bounds cost a few points, not its mesh."""
    positions = np.asarray(mesh.positions, np.float64)
    if len(positions) <= EXTREMES_HULL_VERTICES:
        return positions
    from scipy.spatial import ConvexHull, QhullError
    try:
        return positions[ConvexHull(positions).vertices]
    except (QhullError, ValueError):  # flat or degenerate: every vertex
        return positions


@dataclass(frozen=True)
class DrawView:
    """One draw as the passes that read a draw at a time see it: its node, mesh (with the
    arrays it holds now), world matrix and material."""
    node: Node
    mesh: Mesh
    mesh_arrays: tuple
    world: np.ndarray
    material: Material

    @property
    def bounds(self):
        return self.mesh.bounds(self.world)


class SceneTable:
    def __init__(self):
        self.root = None
        self.edit_serial = -1
        self.stamp = 0                  # syncs so far
        self.structure = 0              # rebuilds so far: draw indices hold from one to the next
        self.draws_changed_at = 0       # the stamp at which any draw's geometry or surface last changed
        self.casters_changed_at = 0     # ... its geometry or alpha cut-out
        self.emitters_changed_at = 0    # ... an emissive draw's geometry or surface, or which draws emit
        self.lights_changed_at = 0
        self._changes = collections.deque()  # (stamp, kind, draws) of the recent changes, oldest first
        self._noted = 0
        self._empty()

    def _empty(self):
        self.nodes, self.rows_of, self.children_of = [], {}, []
        self.parents = np.zeros(0, np.int64)
        self.depths = np.zeros(0, np.int64)
        self.subtree_end = np.zeros(0, np.int64)
        self.local = self.world = np.zeros((0, 4, 4))
        self.meshes, self.mesh_slot, self.mesh_arrays, self.extremes = [], {}, [], []
        self.materials, self.material_slot, self.material_values, self.material_cutouts = [], {}, [], []
        self.material_emits = np.zeros(0, bool)
        self.material_stamp = np.zeros(0, np.int64)  # the stamp at which each material was last edited or added
        self.light_row = np.zeros(0, bool)
        self.draw_rows = np.zeros(0, np.int64)
        self.draw_of_row = np.zeros(0, np.int64)
        self.light_rows = []
        self.lights, self.light_values = [], ()
        self.bounds = (np.zeros(3), np.zeros(3))

    # -- reading ----------------------------------------------------------------------------

    @property
    def draw_count(self):
        return len(self.draw_rows)

    def draw(self, index):
        """Draw `index` as a DrawView."""
        node = self.nodes[self.draw_rows[index]]
        mesh = self.meshes[self.draw_mesh[index]]
        return DrawView(node, mesh, self.mesh_arrays[self.draw_mesh[index]], self.draw_world[index],
                        self.materials[self.draw_material[index]])

    def changed_draws(self, since):
        """The draws whose geometry or surface changed after stamp `since`."""
        return self._changed_since(since, ("geometry", "surface"))

    def changed_casters(self, since):
        """The draws whose geometry or alpha cut-out changed after stamp `since`."""
        return self._changed_since(since, ("geometry", "caster"))

    def _changed_since(self, since, kinds):
        """From the recent changes where they reach back to `since` (a cost that grows with the
        draws changed), else from every draw's stamps."""
        if self._changes and self._changes[0][0] <= since + 1:
            found = [draws for stamp, kind, draws in self._changes if stamp > since and kind in kinds]
            return np.unique(np.concatenate(found)) if found else np.zeros(0, np.int64)
        stamps = {"geometry": self.geometry_stamp, "surface": self.surface_stamp, "caster": self.caster_stamp}
        return np.flatnonzero(np.logical_or.reduce([stamps[kind] > since for kind in kinds]))

    def emissive_draws(self):
        """The draws whose material emits light."""
        return np.flatnonzero(self.material_emits[self.draw_material])

    # -- syncing ----------------------------------------------------------------------------

    def sync(self, scene, rebuild=False):
        """Bring the table up to the scene: from the objects edited since the last sync, or
        anew (`rebuild`, a scene it does not hold, an edit of the graph's shape)."""
        self.stamp += 1
        edited = EDITS.since(self.edit_serial)
        self.edit_serial = EDITS.serial
        if rebuild or scene.root is not self.root or not self._apply(edited):
            self._rebuild(scene.root)

    def _rebuild(self, root):
        self._empty()
        self.root = root
        self.structure += 1
        self._changes.clear()  # a rebuilt table is changed everywhere: its stamps say so
        self._noted = 0
        stamp = self.stamp
        self.draws_changed_at = self.casters_changed_at = self.emitters_changed_at = self.lights_changed_at = stamp
        nodes, parents, depths, ends = [], [], [], []
        stack = [(root, -1, 0)]
        while stack:  # depth first, children in order; a subtree's end is set when its rows are done
            node, parent, depth = stack.pop()
            if node is None:
                ends[parent] = len(nodes)
                continue
            row = len(nodes)
            nodes.append(node)
            parents.append(parent)
            depths.append(depth)
            ends.append(row + 1)
            stack.append((None, row, 0))
            stack.extend((child, row, depth + 1) for child in reversed(node.children))
        self.nodes = nodes
        self.parents, self.depths, self.subtree_end = (np.array(a, np.int64) for a in (parents, depths, ends))
        self.children_of = [tuple(map(id, node.children)) for node in nodes]
        for row, node in enumerate(nodes):
            self.rows_of.setdefault(id(node), []).append(row)
        self.local = transforms.compose_many([n.translation for n in nodes], [n.rotation_deg for n in nodes],
                                             [n.scale for n in nodes])
        self.world = np.empty_like(self.local)
        self._update_world(np.arange(len(nodes)))
        self.draw_rows = np.array([row for row, node in enumerate(nodes) if node.mesh is not None], np.int64)
        self.draw_of_row = np.full(len(nodes), -1, np.int64)
        self.draw_of_row[self.draw_rows] = np.arange(len(self.draw_rows))
        self.draw_mesh = np.array([self._mesh_slot(nodes[row].mesh) for row in self.draw_rows], np.int64)
        self.draw_material = np.array([self._material_slot(nodes[row].material) for row in self.draw_rows], np.int64)
        count = len(self.draw_rows)
        self.draw_world = self.world[self.draw_rows]
        self.draw_bounds = np.zeros((count, 2, 3))
        self._update_bounds(np.arange(count))
        self.geometry_stamp, self.surface_stamp, self.caster_stamp = (np.full(count, stamp, np.int64) for _ in range(3))
        self.light_row = np.array([node.light is not None for node in nodes], bool)
        self.light_rows = np.flatnonzero(self.light_row)
        self._update_lights()

    def _apply(self, edited):
        """Apply edits in place; False where one changes the graph's shape (rebuild instead)."""
        moved_rows, materials, meshes, lights = [], set(), set(), False
        for obj in edited:
            if isinstance(obj, Node):
                rows = self.rows_of.get(id(obj))
                if rows is None:
                    continue
                row = rows[0]
                if self.children_of[row] != tuple(map(id, obj.children)) or self.light_row[row] != (obj.light is not None) \
                        or (self.draw_of_row[row] < 0) != (obj.mesh is None):
                    return False
                for row in rows:
                    moved_rows.append(row)
                    draw = self.draw_of_row[row]
                    if draw >= 0 and self.meshes[self.draw_mesh[draw]] is not obj.mesh:
                        self.draw_mesh[draw] = self._mesh_slot(obj.mesh)
                        meshes.add(int(self.draw_mesh[draw]))
                    if draw >= 0 and self.materials[self.draw_material[draw]] is not obj.material:
                        old = self.draw_material[draw]
                        self.draw_material[draw] = new = self._material_slot(obj.material)
                        self._surface_changed(np.array([draw]), self.material_cutouts[old] != self.material_cutouts[new],
                                              self.material_emits[old] or self.material_emits[new])
                lights = lights or obj.light is not None
            elif isinstance(obj, Material) and id(obj) in self.material_slot:
                materials.add(self.material_slot[id(obj)])
            elif isinstance(obj, Mesh) and id(obj) in self.mesh_slot:
                meshes.add(self.mesh_slot[id(obj)])
            elif isinstance(obj, Light):
                lights = True
        if moved_rows:
            lights = self._move(moved_rows) or lights
        for slot in materials:
            self._material_edited(slot)
        for slot in meshes:
            self._mesh_edited(slot)
        if lights:
            self._update_lights()
        return True

    def _move(self, rows):
        """New local matrices for `rows`, new world matrices for their subtrees; the draws whose
        world matrix changed get new bounds and geometry stamps. True where a light row moved."""
        rows = np.unique(rows)
        nodes = [self.nodes[row] for row in rows]
        self.local[rows] = transforms.compose_many([n.translation for n in nodes], [n.rotation_deg for n in nodes],
                                                   [n.scale for n in nodes])
        subtree = np.unique(np.concatenate([np.arange(row, self.subtree_end[row]) for row in rows]))
        self._update_world(subtree)
        draws = self.draw_of_row[subtree]
        draws = draws[draws >= 0]
        moved = draws[np.any(self.draw_world[draws] != self.world[self.draw_rows[draws]], axis=(1, 2))]
        if len(moved):
            self.draw_world[moved] = self.world[self.draw_rows[moved]]
            self._update_bounds(moved)
            self._geometry_changed(moved)
        return bool(self.light_row[subtree].any())

    def _update_world(self, rows):
        """World matrices of `rows` (whole subtrees, in row order), a depth at a time: each
        row's parent is done before it."""
        depths = self.depths[rows]
        for depth in np.unique(depths):
            at = rows[depths == depth]
            parents = self.parents[at]
            parent_world = np.where((parents >= 0)[:, None, None], self.world[np.maximum(parents, 0)], np.eye(4))
            self.world[at] = np.matmul(parent_world, self.local[at])

    def _update_bounds(self, draws):
        """World bounds of `draws`, a mesh at a time: a mesh that several draws use through its
        extreme vertices (found once), one that a single draw uses through all of them (one
        transform costs less than finding its hull). The scene's bounds follow: found anew from
        every draw only where one of `draws` held or holds a side of them."""
        lo, hi = self.bounds
        before = self.draw_bounds[draws]
        meshes = self.draw_mesh[draws]
        for slot in np.unique(meshes):
            chosen = draws[meshes == slot]
            if np.count_nonzero(self.draw_mesh == slot) > 1:
                if self.extremes[slot] is None:
                    self.extremes[slot] = mesh_extremes(self.meshes[slot])
                points = self.extremes[slot]
            else:
                points = np.asarray(self.meshes[slot].positions, np.float64)
            world = self.draw_world[chosen]
            p = np.matmul(points[None], np.swapaxes(world[:, :3, :3], 1, 2)) + world[:, None, :3, 3]
            self.draw_bounds[chosen, 0] = p.min(axis=1)
            self.draw_bounds[chosen, 1] = p.max(axis=1)
        boxes = np.concatenate([before, self.draw_bounds[draws]])
        if len(self.draw_bounds) == len(draws) or np.any(boxes[:, 0] <= lo) or np.any(boxes[:, 1] >= hi):
            self._update_scene_bounds()

    def _update_scene_bounds(self):
        if self.draw_count:
            self.bounds = (self.draw_bounds[:, 0].min(axis=0), self.draw_bounds[:, 1].max(axis=0))
        else:
            self.bounds = (np.zeros(3), np.zeros(3))

    def _note(self, kind, draws):
        """Record that `draws` changed in `kind` at this stamp, among the recent changes (the
        oldest forgotten past RECENT_CHANGES draws)."""
        self._changes.append((self.stamp, kind, np.asarray(draws, np.int64)))
        self._noted += len(draws)
        while self._noted > RECENT_CHANGES:
            self._noted -= len(self._changes.popleft()[2])

    def _geometry_changed(self, draws):
        self._note("geometry", draws)
        self.geometry_stamp[draws] = self.stamp
        self.draws_changed_at = self.casters_changed_at = self.stamp
        if self.material_emits[self.draw_material[draws]].any():
            self.emitters_changed_at = self.stamp

    def _surface_changed(self, draws, cutout, emission):
        self._note("surface", draws)
        self.surface_stamp[draws] = self.stamp
        self.draws_changed_at = self.stamp
        if cutout:
            self._note("caster", draws)
            self.caster_stamp[draws] = self.stamp
            self.casters_changed_at = self.stamp
        if emission:
            self.emitters_changed_at = self.stamp

    def _material_edited(self, slot):
        material = self.materials[slot]
        values = material_values(material)
        if values == self.material_values[slot]:
            return
        cutout, emits = cutout_values(material), is_emissive(material)
        draws = np.flatnonzero(self.draw_material == slot)
        self._surface_changed(draws, cutout != self.material_cutouts[slot], emits or self.material_emits[slot])
        self.material_values[slot], self.material_cutouts[slot], self.material_emits[slot] = values, cutout, emits
        self.material_stamp[slot] = self.stamp

    def _mesh_edited(self, slot):
        mesh = self.meshes[slot]
        if all(a is b for a, b in zip(self.mesh_arrays[slot], mesh.arrays())) and self.mesh_arrays[slot]:
            return
        self.mesh_arrays[slot] = mesh.arrays()
        self.extremes[slot] = None
        draws = np.flatnonzero(self.draw_mesh == slot)
        self._update_bounds(draws)
        self._geometry_changed(draws)

    def _mesh_slot(self, mesh):
        slot = self.mesh_slot.get(id(mesh))
        if slot is None:
            slot = self.mesh_slot[id(mesh)] = len(self.meshes)
            self.meshes.append(mesh)
            self.mesh_arrays.append(mesh.arrays())
            self.extremes.append(None)  # _update_bounds finds them
        return slot

    def _material_slot(self, material):
        slot = self.material_slot.get(id(material))
        if slot is None:
            slot = self.material_slot[id(material)] = len(self.materials)
            self.materials.append(material)
            self.material_values.append(material_values(material))
            self.material_cutouts.append(cutout_values(material))
            self.material_emits = np.append(self.material_emits, is_emissive(material))
            self.material_stamp = np.append(self.material_stamp, self.stamp)
        return slot

    def _update_lights(self):
        lights = [self.nodes[row].light.placed(self.world[row]) for row in self.light_rows]
        values = tuple(light_values(light) for light in lights)
        if values != self.light_values or len(lights) != len(self.lights):
            self.lights, self.light_values = lights, values
            self.lights_changed_at = self.stamp

