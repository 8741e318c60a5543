"""The scene as arrays, kept up to date from the scene model's edit log (engine.scene.model.EDITS)
instead of a walk of the scene each frame. GL-free: the renderer decides from it which passes a
frame needs, and the GPU copies of the scene (engine/gpu/scene_buffers.py) are written from its rows.

Rows: every node occurrence of the scene graph in depth-first order (a node reached twice has
two rows), each with its parent row, local and world matrices; a subtree is a contiguous run
of rows. Draws: the rows whose node has a mesh, each with the slots of its mesh and material
(each mesh and material once, however many nodes use it), its world matrix and world bounds.
Lights: the rows whose node carries a light, in world space. Posed draws: the draws whose mesh
a pose moves (a skin's joints, morph targets), each with its joint matrices (world(joint)
inverse_bind: a skinned draw's vertices are posed into the world, so its draw matrix is the
identity), its target weights and a box bounding it in its draw's frame, found again where a
joint moved or the node's weights were edited.

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
from ..core.errors import VctError
from .emitters import is_emissive
from .model import EDITS, Light, Material, Mesh, Node

EXTREMES_HULL_VERTICES = 64  # meshes with more vertices are bounded through their convex hull's
RECENT_CHANGES = 1 << 16     # draws of the recent changes kept, to find what changed since a stamp


def _same(a, b):
    """Whether two optional arrays hold the same values."""
    return (a is None) == (b is None) and (a is None or (a.shape == b.shape and np.array_equal(a, b)))


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


@dataclass
class DrawPose:
    """A posed draw's pose: the table rows of its skin's joints (None: not skinned), their
    inverse bind matrices and joint matrices world(joint) inverse_bind (J, 4, 4), its morph
    target weights (None: no targets) and the box (lo, hi) bounding it posed, in its draw's
    frame (the world for a skinned draw)."""
    joint_rows: np.ndarray
    inverse_bind: np.ndarray
    matrices: np.ndarray = None
    weights: np.ndarray = None
    box: tuple = None


def morph_reach(mesh, weights):
    """(lo, hi): how far the morph targets blended by `weights` move a vertex at most along
    each axis (glTF: p = p0 + sum_t w_t dp_t)."""
    lo, hi = np.zeros(3), np.zeros(3)
    for target, weight in zip(mesh.targets, weights):
        if target.positions is not None and weight != 0.0:
            scaled = np.asarray(target.positions, np.float64) * weight
            lo += scaled.min(axis=0)
            hi += scaled.max(axis=0)
    return lo, hi


def joint_boxes(mesh, joint_count):
    """(J, 2, 3): per joint the box of the rest positions of the vertices it moves (empty:
    +inf, -inf)."""
    boxes = np.empty((joint_count, 2, 3))
    boxes[:, 0], boxes[:, 1] = np.inf, -np.inf
    positions = np.asarray(mesh.positions, np.float64)
    joints, weights = np.asarray(mesh.joints, np.int64), np.asarray(mesh.weights, np.float64)
    vertex, column = np.nonzero((weights != 0.0) & (joints < joint_count))
    np.minimum.at(boxes[:, 0], joints[vertex, column], positions[vertex])
    np.maximum.at(boxes[:, 1], joints[vertex, column], positions[vertex])
    return boxes


def posed_box(mesh, pose, boxes):
    """The box bounding a posed mesh in its draw's frame: the rest box (or each joint's box
    under its joint matrix: a blend of points inside the boxes stays inside their bounds),
    widened by the morph targets' reach."""
    reach_lo, reach_hi = morph_reach(mesh, pose.weights) if pose.weights is not None else (np.zeros(3), np.zeros(3))
    if pose.matrices is None:
        positions = np.asarray(mesh.positions, np.float64)
        return positions.min(axis=0) + reach_lo, positions.max(axis=0) + reach_hi
    used = np.all(np.isfinite(boxes), axis=(1, 2))
    lo, hi = boxes[used, 0] + reach_lo, boxes[used, 1] + reach_hi
    corners = np.stack([np.where(np.array([(k >> a) & 1 for a in range(3)], bool), hi, lo) for k in range(8)], axis=1)
    matrices = pose.matrices[used]
    points = np.matmul(corners, np.swapaxes(matrices[:, :3, :3], 1, 2)) + matrices[:, None, :3, 3]
    return points.min(axis=(0, 1)), points.max(axis=(0, 1))


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
        self.draw_skinned = np.zeros(0, bool)
        self.posed_draws = np.zeros(0, np.int64)
        self.poses = {}         # posed draw -> DrawPose
        self.posed_by_row = {}  # a joint's row -> the skinned draws it moves
        self.pose_shapes = {}   # mesh slot -> its joint_boxes
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
        self._place_poses()
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
                draw = self.draw_of_row[row]
                if draw >= 0 and (self._skinned(obj) != self.draw_skinned[draw] or obj.mesh.posed != (draw in self.poses)
                                  or (self._skinned(obj) and obj.skin is not self.nodes[row].skin)):
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
                slot = self.mesh_slot[id(obj)]
                if obj.posed != any(int(draw) in self.poses for draw in np.flatnonzero(self.draw_mesh == slot)):
                    return False
                meshes.add(slot)
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
        draws = draws[(draws >= 0)]
        unskinned = draws[~self.draw_skinned[draws]]
        moved = unskinned[np.any(self.draw_world[unskinned] != self.world[self.draw_rows[unskinned]], axis=(1, 2))]
        if len(moved):
            self.draw_world[moved] = self.world[self.draw_rows[moved]]
        reposed = self._repose(subtree, rows)
        moved = np.union1d(moved, reposed)
        if len(moved):
            self._update_bounds(moved)
            self._geometry_changed(moved)
        return bool(self.light_row[subtree].any())

    # -- poses

    def _skinned(self, node):
        return node.skin is not None and node.mesh is not None and node.mesh.joints is not None

    def _place_poses(self):
        """The DrawPose of every posed draw, with its joints' rows; a skinned draw's matrix the
        identity."""
        self.draw_skinned = np.array([self._skinned(self.nodes[row]) for row in self.draw_rows], bool)
        self.posed_draws = np.array([draw for draw, row in enumerate(self.draw_rows) if self.nodes[row].mesh.posed], np.int64)
        for draw in self.posed_draws:
            node = self.nodes[self.draw_rows[draw]]
            joint_rows, inverse_bind = None, None
            if self.draw_skinned[draw]:
                joint_rows = []
                for joint in node.skin.joints:
                    rows = self.rows_of.get(id(joint))
                    if rows is None:
                        raise VctError(f'joint "{joint.name}" of its skin "{node.skin.name}" is not in the scene',
                                       field=f'node "{node.name}".skin')
                    joint_rows.append(rows[0])
                    self.posed_by_row.setdefault(rows[0], []).append(int(draw))
                joint_rows = np.array(joint_rows, np.int64)
                inverse_bind = np.asarray(node.skin.inverse_bind_matrices, np.float64)
                self.draw_world[draw] = np.eye(4)
            self.poses[int(draw)] = DrawPose(joint_rows, inverse_bind)
            self._pose_values(int(draw))

    def _pose_values(self, draw):
        """Compute a posed draw's joint matrices and weights; True where they changed."""
        node = self.nodes[self.draw_rows[draw]]
        mesh, pose = node.mesh, self.poses[draw]
        matrices = None if pose.joint_rows is None else np.matmul(self.world[pose.joint_rows], pose.inverse_bind)
        weights = None
        if mesh.targets:
            given = node.morph_weights if node.morph_weights is not None else mesh.target_weights
            weights = np.zeros(len(mesh.targets))
            if given is not None:
                given = np.asarray(given, np.float64).ravel()[:len(weights)]
                weights[:len(given)] = given
        changed = not (_same(matrices, pose.matrices) and _same(weights, pose.weights))
        pose.matrices, pose.weights = matrices, weights
        return changed

    def _repose(self, subtree, edited_rows):
        """The posed draws whose pose changed: those whose joints lie in `subtree` (rows whose
        world matrices were just updated) and those of the edited rows (their weights)."""
        if not self.poses:  # a scene without skins or morph targets: nothing to look at
            return np.zeros(0, np.int64)
        joint_rows = np.fromiter(self.posed_by_row, np.int64, len(self.posed_by_row))
        candidates = {draw for row in joint_rows[np.isin(joint_rows, subtree)].tolist() for draw in self.posed_by_row[row]}
        for row in np.asarray(edited_rows).tolist():
            draw = int(self.draw_of_row[row])
            if draw in self.poses:
                candidates.add(draw)
        return np.array(sorted(draw for draw in candidates if self._pose_values(draw)), np.int64)

    def pose(self, draw):
        """The DrawPose of a posed draw."""
        return self.poses[int(draw)]

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
        for draw in draws[np.isin(draws, self.posed_draws)]:
            self._update_posed_bounds(int(draw))
        unposed = draws[~np.isin(draws, self.posed_draws)]
        meshes = self.draw_mesh[unposed]
        for slot in np.unique(meshes):
            chosen = unposed[meshes == slot]
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

    def _update_posed_bounds(self, draw):
        """A posed draw's box in its frame (posed_box) and world bounds."""
        mesh, pose = self.meshes[self.draw_mesh[draw]], self.poses[draw]
        boxes = None
        if pose.matrices is not None:
            slot = int(self.draw_mesh[draw])
            if slot not in self.pose_shapes or len(self.pose_shapes[slot]) < len(pose.matrices):
                self.pose_shapes[slot] = joint_boxes(mesh, len(pose.matrices))
            boxes = self.pose_shapes[slot][:len(pose.matrices)]
        pose.box = posed_box(mesh, pose, boxes)
        corners = np.array([[pose.box[(k >> a) & 1][a] for a in range(3)] for k in range(8)])
        world = self.draw_world[draw]
        points = corners @ world[:3, :3].T + world[:3, 3]
        self.draw_bounds[draw] = points.min(axis=0), points.max(axis=0)

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
        self.pose_shapes.pop(slot, None)
        draws = np.flatnonzero(self.draw_mesh == slot)
        for draw in draws[np.isin(draws, self.posed_draws)]:
            self._pose_values(int(draw))
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

