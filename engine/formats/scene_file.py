"""Scene files -> scene model: a JSON scene file, or a model file (glTF/GLB with its cameras
and lights, OBJ, PLY, STL, OFF) as a whole scene.

A JSON file is checked against the scene format's schema (engine/formats/scene_schema.py: fields,
types, ranges, defaults) and then for what a schema cannot say (materials named but not
defined, degenerate quads, world transforms, the files it names). A glTF file is read by
engine/formats/gltf/ with its cameras and KHR_lights_punctual lights; its nodes are held to the
same limits. The camera: the JSON file's, else the first camera of its mesh files (depth
first), else one framing the scene's bounds (with a warning); `camera=NAME` picks a camera node
by name instead. A JSON file's mesh files bring their lights unless it lists lights itself.
Every fault raises SceneError naming the file and the field, e.g. `scenes/x.json: objects[6]
"Short Box".size[0]: must be positive`."""
import dataclasses
import json
from pathlib import Path

import numpy as np

from ..core.errors import SceneError, warn
from ..core.limits import MATERIAL_RANGES, MAX_DEPTH, MAX_SCENE_BYTES, check_material, check_placement
from ..scene.model import Camera, Clipmap, Environment, Light, Material, Node, Scene, VoxelRegion, box_mesh, quad_mesh, sphere_mesh
from .input_files import InputFiles, os_problem, read_radiance_map
from .mesh_files import MESH_SUFFIXES, load_mesh_file

# The image of a camera that a glTF file gives no size: this wide, its aspect ratio the
# camera's (glTF aspectRatio, or xmag / ymag), else FALLBACK_ASPECT.
DEFAULT_WIDTH = 640
FALLBACK_ASPECT = 4.0 / 3.0
FRAMING_FOV_DEG = 45.0
from .scene_schema import LIGHT_TYPES, default, validate


class _Constant:
    """A NaN/Infinity token (Python's json accepts them; JSON does not): kept in place while
    parsing so the loader can name the field it stood in."""

    def __init__(self, text):
        self.text = text


def _find_constant(document):
    """(field, token) of the first NaN/Infinity token in a parsed document that holds one.
    Walks with its own stack: a document may nest as deep as the JSON parser allows."""
    stack = [("", document)]
    while stack:
        where, value = stack.pop()
        if isinstance(value, _Constant):
            return where, value.text
        if isinstance(value, dict):
            items = [(f"{where}.{key}" if where else key, item) for key, item in value.items()]
        elif isinstance(value, list):
            items = [(f"{where}[{i}]", item) for i, item in enumerate(value)]
        else:
            continue
        stack.extend(reversed(items))


def _too_deep(document):
    """The field of the first node nested more than MAX_DEPTH levels below the top, or None.
    Walks with its own stack, before the schema (whose node definition recurses)."""
    stack = [(key, document.get(key), 1) for key in ("lights", "objects")]
    while stack:
        field, nodes, depth = stack.pop()
        if not isinstance(nodes, list):
            continue
        for i, node in reversed(list(enumerate(nodes))):
            if not isinstance(node, dict):
                continue
            name = node.get("name")
            where = f"{field}[{i}]" + (f' "{name}"' if isinstance(name, str) else "")
            if depth > MAX_DEPTH:
                return where
            stack.append((f"{where}.children", node.get("children"), depth + 1))
    return None


def parse_scene_file(path, inputs):
    """The parsed JSON of the scene file at `path`, read through `inputs`: a JSON object
    without NaN or Infinity tokens, its nodes at most MAX_DEPTH deep, valid by the schema."""
    try:
        data = inputs.read(path, MAX_SCENE_BYTES)
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        raise SceneError(f"cannot read scene file ({os_problem(exc)})", source=path) from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneError(f"not UTF-8 text (byte {exc.start})", source=path) from None
    constants = []  # the NaN/Infinity tokens met while parsing

    def constant(token):
        constants.append(_Constant(token))
        return constants[-1]

    try:
        document = json.loads(text, parse_constant=constant)
    except json.JSONDecodeError as exc:
        raise SceneError(f"malformed JSON: {exc.msg}", source=path, field=f"line {exc.lineno} column {exc.colno}") from None
    except ValueError as exc:
        raise SceneError(f"malformed JSON: {exc}", source=path) from None
    except RecursionError:
        raise SceneError("malformed JSON: nested too deeply", source=path) from None
    if constants:
        field, token = _find_constant(document)
        raise SceneError(f"malformed JSON: {token} is not a JSON number (JSON has no NaN or Infinity)",
                         source=path, field=field)
    if not isinstance(document, dict):
        raise SceneError("the scene must be a JSON object", source=path)
    deep = _too_deep(document)
    if deep is not None:
        raise SceneError(f"children nest more than {MAX_DEPTH} levels deep", source=path, field=deep)
    validate(document, path)
    return document


def load_scene(path, camera=None):
    """Load a scene file (JSON, or a model file as a whole scene: MESH_SUFFIXES) into a Scene (pure Python/numpy,
    no GL); `camera`: the name of the camera node to render from (None: the scene's own)."""
    path = Path(path)
    scene_file = _SceneFile(path)
    scene = scene_file.model_scene() if path.suffix.lower() in MESH_SUFFIXES else scene_file.scene()
    if camera is not None:
        scene.camera = scene_file.named_camera(scene, camera)
    return scene


def _vector(spec, key, definition):
    """spec[key] as a float array, or the schema's default for the field."""
    return np.array(spec[key] if key in spec else default(definition, key), float)


def _value(spec, key, definition):
    return spec[key] if key in spec else default(definition, key)


def _title(name):
    return " ".join(word.capitalize() for word in name.replace("_", " ").split()) or "Scene"


class _SceneFile:
    """One scene file being loaded: its path, the files it reads, its materials and meshes."""

    def __init__(self, path):
        self.path = path
        self.inputs = InputFiles()
        self.file_lights = True  # whether the lights of the mesh files are the scene's
        self.materials = {}
        self.meshes = {}  # primitive meshes by type, mesh files by (path, material)

    def fail(self, field, message):
        raise SceneError(message, source=self.path, field=field)

    def scene(self):
        data = parse_scene_file(self.path, self.inputs)
        self.file_lights = "lights" not in data
        for key, spec in data.get("materials", {}).items():
            self.materials[key] = self.material(key, spec, f"materials.{key}")
        name = data.get("name", self.path.stem)
        root = Node(name=_title(name))
        for key in ("objects", "lights"):
            for i, spec in enumerate(data.get(key, [])):
                root.children.append(self.node(spec, f"{key}[{i}]", np.eye(4), 1))
        region, clipmap = self.voxel_region(data["voxel_region"]) if "voxel_region" in data else (None, None)
        environment = self.environment(data["environment"]) if "environment" in data else None
        scene = Scene(name=name, root=root, camera=None, materials=self.materials, voxel_region=region, clipmap=clipmap,
                      environment=environment, source=str(self.path), files=tuple(self.inputs.paths))
        scene.camera = self.camera(data["camera"]) if "camera" in data else self.file_camera(scene)
        return scene

    def voxel_region(self, spec):
        """(VoxelRegion or None, Clipmap or None) of a `voxel_region`: a grid's cube (center and
        size) or a clipmap, not both."""
        if "clipmap" in spec:
            other = next((key for key in ("center", "size") if key in spec), None)
            if other is not None:
                self.fail(f"voxel_region.{other}", f"a clipmap is centred on the camera: give {other} or clipmap, not both")
            c = spec["clipmap"]
            return None, Clipmap(int(c["levels"]), int(c["resolution"]), float(c["voxel_size"]))
        for key in ("center", "size"):
            if key not in spec:
                self.fail(f"voxel_region.{key}", "missing (a grid's cube takes center and size)")
        return VoxelRegion(np.array(spec["center"], float), float(spec["size"])), None

    def model_scene(self):
        """A model file as a whole scene: its nodes (with a glTF file's cameras and lights)
        under a root node named after the file; held to the scene file's limits
        (engine.core.limits)."""
        root = Node(name=_title(self.path.stem))
        root.children = load_mesh_file(self.path, str(self.path), None, self.inputs)
        for part in root.children:
            self.check_file_nodes(part, np.eye(4), 1, "")
        if not root.children or not any(n.mesh is not None for n, _ in root.walk()):
            self.fail("", "holds no triangles")
        scene = Scene(name=self.path.stem, root=root, camera=None, materials={}, source=str(self.path),
                      files=tuple(self.inputs.paths))
        scene.camera = self.file_camera(scene, framed_silently=True)
        return scene

    def file_camera(self, scene, framed_silently=False):
        """The first camera node of the scene (depth first) placed in the world, at its image
        size (the scene's camera_node: the camera follows it when the scene is posed); or, where
        it has none, one framing the scene's bounds, with a warning unless `framed_silently`
        (a model file, which is framed as model viewers frame it)."""
        cameras = scene.cameras()
        if cameras:
            node, world = cameras[0]
            scene.camera_node = node
            return _placed(node, world)
        if not framed_silently:
            warn("no camera: rendering from one that frames the scene's bounds", source=self.path)
        return framing_camera(scene.bounds(), DEFAULT_WIDTH, round(DEFAULT_WIDTH / FALLBACK_ASPECT))

    def named_camera(self, scene, name):
        """The camera node called `name`, placed; SceneError listing the cameras where none is."""
        for node, world in scene.cameras():
            if node.name == name or node.camera.name == name:
                scene.camera_node = node
                return _placed(node, world)
        names = ", ".join(f'"{node.name}"' for node, _ in scene.cameras()) or "none"
        self.fail("camera", f'no camera node named "{name}" (the scene has: {names})')

    def environment(self, spec):
        if ("radiance" in spec) == ("map" in spec):
            self.fail("environment", 'give "radiance" (a uniform sky) or "map" (an equirectangular image), one of them')
        environment = Environment(scale=float(_value(spec, "scale", "environment")),
                                  rotation_y_deg=float(_value(spec, "rotation_y_deg", "environment")))
        if "radiance" in spec:
            environment.radiance = np.array(spec["radiance"], float)
            return environment
        try:
            environment.image = read_radiance_map(self.path.parent / spec["map"], self.inputs)
        except (OSError, ValueError) as exc:  # ValueError: a NUL in the name, or an image that is no radiance map
            self.fail("environment.map", f'"{spec["map"]}": {os_problem(exc)}')
        environment.name = f'{self.path}: environment.map "{spec["map"]}"'
        return environment

    def material(self, key, spec, field):
        material = Material(
            name=key,
            albedo=_vector(spec, "albedo", "material"),
            roughness=float(_value(spec, "roughness", "material")),
            metalness=float(_value(spec, "metalness", "material")),
            specular=float(_value(spec, "specular", "material")),
            emission=_vector(spec, "emission", "material"),
            double_sided=_value(spec, "double_sided", "material"),
        )
        check_material(material, self.fail, {name: f"{field}.{name}" for name in MATERIAL_RANGES})
        return material

    def camera(self, spec):
        camera = Camera(
            position=_vector(spec, "position", "camera"),
            look_at=_vector(spec, "look_at", "camera"),
            up=_vector(spec, "up", "camera"),
            vertical_fov_deg=float(_value(spec, "vertical_fov_deg", "camera")),
            width=int(_value(spec, "width", "camera")),
            height=int(_value(spec, "height", "camera")),
        )
        forward = camera.look_at - camera.position
        if np.linalg.norm(forward) == 0:
            self.fail("camera.look_at", "must differ from camera.position")
        if np.linalg.norm(np.cross(forward, camera.up)) < 1e-9 * np.linalg.norm(forward):
            self.fail("camera.up", "must not be parallel to the viewing direction")
        return camera

    def node(self, spec, field, parent_world, depth):
        """The node of `spec` with its children; `parent_world` places it, `depth` counts the
        levels down to it (1: a top-level object or light)."""
        kind = spec["type"]
        name = spec.get("name", f"{kind} {field}")
        field = f'{field} "{name}"' if "name" in spec else field
        node = Node(name=name, translation=_vector(spec, "translation", kind), rotation_deg=_vector(spec, "rotation", kind),
                    scale=_vector(spec, "scale", kind))
        file_nodes = []
        if kind in LIGHT_TYPES:
            node.light = self.light(spec, field, kind)
        elif kind != "group":
            if "material" in spec:  # a mesh file without one has its own materials
                if spec["material"] not in self.materials:
                    self.fail(f"{field}.material", f'unknown material "{spec["material"]}"')
                node.material = self.materials[spec["material"]]
            if kind == "mesh":
                file_nodes = self.mesh_file(spec, field, node)
            else:
                node.mesh = self.shape(spec, field, kind, node)
        world = parent_world @ node.local_matrix()
        check_placement(node, world, self.placement_failure(field))
        for part in file_nodes:
            self.check_file_nodes(part, world, depth + 1, f"{field}.file: {spec['file']}")
        for i, child in enumerate(spec.get("children", [])):
            node.children.append(self.node(child, f"{field}.children[{i}]", world, depth + 1))
        return node

    def placement_failure(self, field):
        """check_placement's `fail` for the node at `field`."""
        return lambda attribute, message: self.fail(f"{field}.{attribute}" if attribute else field, message)

    def check_file_nodes(self, top, parent_world, depth, where):
        """The limits of the scene's own nodes (engine.core.limits: depth, world transforms, reach)
        for the nodes a mesh file added below a node, `top` at `depth`; `where` names the file."""
        stack = [(top, parent_world, depth)]
        while stack:
            node, parent, level = stack.pop()
            field = f'{where}: node "{node.name}"' if where else f'node "{node.name}"'
            if level > MAX_DEPTH:
                self.fail(field, f"nests more than {MAX_DEPTH} levels deep (the scene's levels above it counted in)")
            world = parent @ node.local_matrix()
            check_placement(node, world, self.placement_failure(field))
            if node.light is not None and not self.file_lights:  # the scene file lists its own lights
                node.light = None
            stack.extend((child, world, level + 1) for child in reversed(node.children))

    def shape(self, spec, field, kind, node):
        """The mesh of a quad, box or sphere; boxes and spheres scale and place `node`."""
        if kind == "quad":
            v = np.array(spec["vertices"], float)
            a = np.cross(v[1] - v[0], v[2] - v[0])
            b = np.cross(v[2] - v[0], v[3] - v[0])
            scale = max(np.ptp(v, axis=0).max(), 1e-30) ** 2
            if np.linalg.norm(a) < 1e-9 * scale or np.linalg.norm(b) < 1e-9 * scale or np.dot(a, b) <= 0:
                self.fail(f"{field}.vertices", "degenerate quad (zero area, collinear or folded vertices)")
            return quad_mesh(v)
        node.translation = node.translation + _vector(spec, "center", kind)
        if kind == "box":
            node.rotation_deg = node.rotation_deg + np.array([0.0, float(_value(spec, "rotation_y_deg", kind)), 0.0])
            node.scale = node.scale * np.array(spec["size"], float)
            return self._primitive("box", box_mesh)
        node.scale = node.scale * float(spec["radius"])
        return self._primitive("sphere", sphere_mesh)

    def _primitive(self, kind, make):
        """The one mesh every box (or sphere) of the scene shares, made at the first."""
        if kind not in self.meshes:
            self.meshes[kind] = make()
        return self.meshes[kind]

    def mesh_file(self, spec, field, node):
        """The file's nodes under `node`, all with `node.material` where it has one; a file
        that is one part in its own frame (one OBJ material group, a PLY, a glTF node with one
        primitive) becomes `node`'s own mesh and material instead. A file is read once however
        many objects use it with the same material: they share its meshes and materials.
        Returns the nodes added under `node`."""
        relative = spec["file"]
        where = f"{field}.file"
        try:
            path = (self.path.parent / relative).resolve()
        except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
            self.fail(where, f'cannot read mesh "{relative}" ({os_problem(exc)})')
        key = (path, id(node.material))
        if key in self.meshes:  # the file's nodes for a later use: copies of the first use's
            parts = [_copy_tree(part) for part in self.meshes[key]]
        else:
            try:
                parts = self.meshes[key] = load_mesh_file(path, relative, node.material, self.inputs)
            except SceneError as exc:
                self.fail(where, str(exc))
        if not any(n.mesh is not None for part in parts for n in part.nodes()):
            self.fail(where, f'{relative}: holds no triangles')
        if len(parts) == 1 and not parts[0].children and np.array_equal(parts[0].local_matrix(), np.eye(4)):
            node.mesh, node.material = parts[0].mesh, parts[0].material
            return []
        node.children.extend(parts)
        return parts

    def light(self, spec, field, kind):
        light = Light(type=kind, intensity=np.array(spec["intensity" if kind != "directional" else "irradiance"], float))
        if kind in ("point", "spot"):
            light.position = _vector(spec, "position", kind)
            light.range = float(_value(spec, "range", kind))
        if kind in ("spot", "directional"):
            direction = np.array(spec["direction"], float)
            if np.linalg.norm(direction) == 0:
                self.fail(f"{field}.direction", "must not be zero")
            light.direction = direction / np.linalg.norm(direction)
        if kind == "spot":
            light.outer_angle_deg = float(_value(spec, "outer_angle_deg", kind))
            light.inner_angle_deg = float(spec.get("inner_angle_deg", 0.8 * light.outer_angle_deg))
            if light.inner_angle_deg > light.outer_angle_deg:
                self.fail(f"{field}.inner_angle_deg", f"must be at most outer_angle_deg ({light.outer_angle_deg:g})")
        light.cast_shadows = _value(spec, "cast_shadows", kind)
        return light


def _placed(node, world):
    """The Camera of a camera node, named after the node, at the image size its aspect ratio
    gives."""
    aspect = node.camera.aspect_ratio or FALLBACK_ASPECT
    camera = node.camera.placed(world, DEFAULT_WIDTH, max(1, round(DEFAULT_WIDTH / aspect)))
    camera.name = node.name
    return camera


def framing_camera(bounds, width, height):
    """A perspective camera that sees the whole bounding sphere of `bounds` from the front (+z)
    and a little above."""
    lo, hi = (np.asarray(b, float) for b in bounds)
    center = (lo + hi) / 2.0
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 1e-3)
    direction = np.array([0.0, 0.25, 1.0]) / np.linalg.norm([0.0, 0.25, 1.0])
    distance = radius / np.sin(np.radians(FRAMING_FOV_DEG) / 2.0)
    return Camera(position=center + direction * distance, look_at=center, up=np.array([0.0, 1.0, 0.0]),
                  vertical_fov_deg=FRAMING_FOV_DEG, width=width, height=height, name="framing")


def _copy_tree(node):
    """A copy of the nodes (their own transforms), sharing meshes, materials and lights."""
    copy = dataclasses.replace(node, translation=node.translation.copy(), rotation_deg=node.rotation_deg.copy(),
                               scale=node.scale.copy(), children=[])
    copy.children = [_copy_tree(child) for child in node.children]
    return copy
