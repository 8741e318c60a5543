"""The node hierarchy of a glTF file's scene, and the animations that move its nodes."""
import numpy as np

from ...core.errors import warn
from ...core.limits import MAX_DEPTH
from ...core.progress import progress
from ...core.transforms import decompose, euler_deg_from_rotation, quaternion_rotation
from ...scene.animation import INTERPOLATIONS, PATHS, NodeTracks, Sampler
from ...scene.model import Node, Skin
from .container import FLOAT

NORMALIZED_ROTATION_TYPES = (5120, 5121, 5122, 5123)  # animation rotations may be signed too


def _rest(node):
    """A node's pose before any animation: (translation, rotation_deg, scale, morph weights)."""
    weights = None if node.morph_weights is None else np.array(node.morph_weights)
    return node.translation.copy(), node.rotation_deg.copy(), node.scale.copy(), weights


class NodeReader:
    """Part of GltfFile: the default scene's nodes, their transforms, meshes, cameras and lights,
    and the animation channels that move them."""

    def nodes(self):
        """The default scene's (else the first scene's, else every parentless node's) nodes."""
        nodes = self.list("nodes")
        scenes = self.list("scenes")
        if scenes:
            index = self.json.index(self.doc, "scene", "", "scenes", len(scenes), 0)
            spec = self.element("scenes", index)
            roots = self.json.get(spec, "nodes", f"scenes[{index}]", [], list)
            where = f"scenes[{index}].nodes"
        else:
            children = {c for i in range(len(nodes))
                        for c in self.json.get(self.element("nodes", i), "children", f"nodes[{i}]", [], list)}
            roots = [i for i in range(len(nodes)) if i not in children]
            where = "nodes"
        # node() counts each node it places, its mesh made: the bar of a file that loads long.
        with progress(len(nodes), str(self.json.path), "node", summary=False) as self.placing:
            result = [self.node(self.json.index_value(root, f"{where}[{k}]", "nodes", len(nodes)), 1)
                      for k, root in enumerate(roots)]
        self.attach_skins()
        self.animate()
        self.buffers.clear()
        if self.positionless:
            warn(f"{len(self.positionless)} primitive{'s' if len(self.positionless) > 1 else ''} without POSITION not drawn "
                 f"(as glTF says): {', '.join(self.positionless[:3])}{', ...' if len(self.positionless) > 3 else ''}",
                 source=self.json.path)
        return result

    def node(self, index, depth):
        """nodes[index] with its children, `depth` levels down from the scene's roots (1)."""
        field = f"nodes[{index}]"
        if index in self.placed:
            self.fail(field, "has more than one parent, or is its own ancestor (glTF nodes form trees)")
        if depth > MAX_DEPTH:
            self.fail(field, f"nests more than {MAX_DEPTH} levels deep")
        self.placed.add(index)
        spec = self.element("nodes", index)
        node = self.node_objects[index] = Node(name=self.json.get(spec, "name", field, field, str))
        if "matrix" in spec:
            matrix = self.json.vector(spec, "matrix", field, length=16).reshape(4, 4).T  # column-major
            trs = decompose(matrix)
            if trs is None:
                self.fail(f"{field}.matrix", "is not a translation, rotation and scale (glTF requires one)")
            node.translation, node.rotation_deg, node.scale = trs
        else:
            node.translation = self.json.vector(spec, "translation", field, [0.0, 0.0, 0.0])
            rotation = self.json.vector(spec, "rotation", field, [0.0, 0.0, 0.0, 1.0], length=4)
            if not 0.5 <= np.linalg.norm(rotation) <= 2.0:
                self.fail(f"{field}.rotation", "must be a unit quaternion x, y, z, w")
            node.rotation_deg = euler_deg_from_rotation(quaternion_rotation(rotation))
            node.scale = self.json.vector(spec, "scale", field, [1.0, 1.0, 1.0])
        if "camera" in spec:
            node.camera = self.camera(self.json.index(spec, "camera", field, "cameras", len(self.list("cameras"))))
        lights = self.json.get(self.json.get(spec, "extensions", field, {}, dict), "KHR_lights_punctual",
                               f"{field}.extensions", {}, dict)
        if "light" in lights:
            node.light = self.light(self.json.index(lights, "light", f"{field}.extensions.KHR_lights_punctual", "lights",
                                                    len(self.punctual_lights())))
        if "mesh" in spec:
            parts = self.mesh(self.json.index(spec, "mesh", field, "meshes", len(self.list("meshes"))))
            if len(parts) == 1:
                node.mesh, node.material = parts[0]
                carriers = [node]
            else:
                carriers = [Node(name=f"{node.name}: {material.name}", mesh=mesh, material=material) for mesh, material in parts]
                node.children += carriers
            self.mesh_nodes[index] = carriers
            if "weights" in spec:
                for carrier in carriers:
                    if carrier.mesh.targets:
                        carrier.morph_weights = self.json.vector_value(spec["weights"], f"{field}.weights", len(carrier.mesh.targets))
            if "skin" in spec:
                self.skinned.append((index, self.json.index(spec, "skin", field, "skins", len(self.list("skins")))))
        self.placing.update()
        children = self.json.get(spec, "children", field, [], list)
        for k, child in enumerate(children):
            child = self.json.index_value(child, f"{field}.children[{k}]", "nodes", len(self.list("nodes")))
            node.children.append(self.node(child, depth + 1))
        return node

    # -- skins

    def attach_skins(self):
        """Give the nodes drawing a skinned glTF node's primitives its Skin (each skin made
        once), its joints nodes of the scene, every joint a vertex names among them."""
        skins = {}
        for index, s in self.skinned:
            if s not in skins:
                skins[s] = self.skin(s)
            for carrier in self.mesh_nodes.get(index, []):
                if carrier.mesh.joints is None:
                    continue
                if int(carrier.mesh.joints.max()) >= len(skins[s].joints):
                    self.fail(f"nodes[{index}].skin", f"a vertex names joint {int(carrier.mesh.joints.max())}, skins[{s}] has "
                                                     f"{len(skins[s].joints)}")
                carrier.skin = skins[s]

    def skin(self, index):
        field = f"skins[{index}]"
        spec = self.element("skins", index)
        joints = []
        for k, joint in enumerate(self.json.get(spec, "joints", field, kind=list)):
            joint = self.json.index_value(joint, f"{field}.joints[{k}]", "nodes", len(self.list("nodes")))
            if joint not in self.node_objects:
                self.fail(f"{field}.joints[{k}]", f"nodes[{joint}] is not in the scene drawn")
            joints.append(self.node_objects[joint])
        if not joints:
            self.fail(f"{field}.joints", "must not be empty")
        if "inverseBindMatrices" in spec:
            matrices = self.accessor(spec, "inverseBindMatrices", field, ("MAT4",), FLOAT).astype(np.float64)
            if len(matrices) != len(joints):
                self.fail(f"{field}.inverseBindMatrices", f"has {len(matrices)} matrices for {len(joints)} joints")
            matrices = matrices.reshape(-1, 4, 4).transpose(0, 2, 1)  # column-major
        else:
            matrices = np.tile(np.eye(4), (len(joints), 1, 1))
        return Skin(joints, matrices, self.json.get(spec, "name", field, field, str))

    # -- animations

    def animate(self):
        """Give the placed nodes that the file's animations move their NodeTracks; a weights
        channel moves the nodes drawing the glTF node's primitives."""
        tracks = {}  # node index -> {animation name: {path: Sampler}}
        weight_tracks = {}  # id(Node) drawing a primitive -> (Node, {animation name: {"weights": Sampler}})
        for a in range(len(self.list("animations"))):
            field = f"animations[{a}]"
            spec = self.element("animations", a)
            name = self.json.get(spec, "name", field, f"animation {a}", str)
            samplers = self.json.get(spec, "samplers", field, kind=list)
            for c, channel in enumerate(self.json.get(spec, "channels", field, kind=list)):
                where = f"{field}.channels[{c}]"
                if not isinstance(channel, dict):
                    self.fail(where, "must be an object")
                target = self.json.get(channel, "target", where, kind=dict)
                path = self.json.get(target, "path", f"{where}.target", kind=str)
                if path not in PATHS and "extensions" in target:  # an extension's target (KHR_animation_pointer)
                    continue
                if path not in PATHS:
                    self.fail(f"{where}.target.path", f'must be "translation", "rotation", "scale" or "weights", got "{path}"')
                if "node" not in target:  # glTF: a channel without a node is left to extensions
                    continue
                node = self.json.index(target, "node", f"{where}.target", "nodes", len(self.list("nodes")))
                s = self.json.index(channel, "sampler", where, f"{field}.samplers", len(samplers))
                if node not in self.node_objects:  # a node of another scene of the file is not drawn
                    continue
                if path == "weights":
                    morphed = [carrier for carrier in self.mesh_nodes.get(node, []) if carrier.mesh.targets]
                    if not morphed:
                        self.fail(f"{where}.target", f"nodes[{node}] draws no mesh with morph targets")
                    sampler = self.sampler(samplers[s], f"{field}.samplers[{s}]", path, len(morphed[0].mesh.targets))
                    for carrier in morphed:
                        weight_tracks.setdefault(id(carrier), (carrier, {}))[1].setdefault(name, {})["weights"] = sampler
                    continue
                sampler = self.sampler(samplers[s], f"{field}.samplers[{s}]", path)
                tracks.setdefault(node, {}).setdefault(name, {})[path] = sampler
        for index, by_name in tracks.items():
            node = self.node_objects[index]
            if id(node) in weight_tracks:
                for animation, samplers in weight_tracks.pop(id(node))[1].items():
                    by_name.setdefault(animation, {}).update(samplers)
            node.animation = NodeTracks(_rest(node), by_name)
        for node, by_name in weight_tracks.values():
            node.animation = NodeTracks(_rest(node), by_name)

    def sampler(self, spec, field, path, targets=1):
        """The Sampler of an animation sampler that moves a node's `path`: input times strictly
        increasing, outputs one per time (three with CUBICSPLINE; `targets` scalars each for
        weights), each within the limits of a node's translation, unit rotation or scale."""
        if not isinstance(spec, dict):
            self.fail(field, "must be an object")
        interpolation = self.json.get(spec, "interpolation", field, "LINEAR", str)
        if interpolation not in INTERPOLATIONS:
            self.fail(f"{field}.interpolation", f'must be one of {", ".join(INTERPOLATIONS)}, got "{interpolation}"')
        times = self.accessor(spec, "input", field, ("SCALAR",), FLOAT)[:, 0].astype(np.float64)
        if np.any(times < 0) or np.any(np.diff(times) <= 0):
            self.fail(f"{field}.input", "times must be non-negative and strictly increasing")
        kind = {"rotation": ("VEC4",), "weights": ("SCALAR",)}.get(path, ("VEC3",))
        values = self.accessor(spec, "output", field, kind,
                               FLOAT + (NORMALIZED_ROTATION_TYPES if path in ("rotation", "weights") else ())).astype(np.float64)
        per_time = 3 if interpolation == "CUBICSPLINE" else 1
        if path == "weights":
            if len(values) != per_time * len(times) * targets:
                self.fail(f"{field}.output", f"has {len(values)} elements; {interpolation} over {len(times)} input times "
                                             f"and {targets} morph targets needs {per_time * len(times) * targets}")
            values = values.reshape(len(times), per_time, targets)
            return Sampler(times, values if per_time == 3 else values[:, 0], interpolation, rotation=False)
        if len(values) != per_time * len(times):
            self.fail(f"{field}.output", f"has {len(values)} elements; {interpolation} over {len(times)} input times "
                                         f"needs {per_time * len(times)}")
        if path == "rotation":
            keyframes = values.reshape(len(times), per_time, 4)[:, per_time // 2]
            if not np.all((0.5 <= np.linalg.norm(keyframes, axis=1)) & (np.linalg.norm(keyframes, axis=1) <= 2.0)):
                self.fail(f"{field}.output", "rotations must be unit quaternions x, y, z, w")
        if per_time == 3:
            values = values.reshape(len(times), 3, -1)
        return Sampler(times, values, interpolation, rotation=path == "rotation")

