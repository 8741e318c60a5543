"""JSON scene files -> scene model. Every malformed value raises SceneError naming the
file and the field, e.g. `scenes/x.json: objects[6] "Short Box".size: must be positive`."""
import dataclasses
import json
from pathlib import Path

import numpy as np

from .errors import SceneError
from .input_files import InputFiles, os_problem
from .json_reader import JsonReader
from .limits import MATERIAL_RANGES, MAX_DEPTH, MAX_SCENE_BYTES, MIN_FOV_DEG, MIN_SCALE, check_material, check_placement
from .mesh_files import load_mesh_file
from .scene import Camera, Light, Material, Node, Scene, VoxelRegion, box_mesh, quad_mesh, sphere_mesh

GEOMETRY_TYPES = ("quad", "box", "sphere", "mesh", "group")
LIGHT_TYPES = ("point", "spot", "directional")


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


def load_scene(path):
    """Load a JSON scene file into a Scene (pure Python/numpy, no GL)."""
    path = Path(path)
    reader = JsonReader(path)
    inputs = InputFiles()
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
        data = json.loads(text, parse_constant=constant)
    except json.JSONDecodeError as exc:
        raise SceneError(f"malformed JSON: {exc.msg}", source=path, field=f"line {exc.lineno} column {exc.colno}") from None
    except ValueError as exc:
        raise SceneError(f"malformed JSON: {exc}", source=path) from None
    except RecursionError:
        raise SceneError("malformed JSON: nested too deeply", source=path) from None
    if constants:
        field, token = _find_constant(data)
        reader.fail(field, f"malformed JSON: {token} is not a JSON number (JSON has no NaN or Infinity)")
    if not isinstance(data, dict):
        reader.fail("", "the scene must be a JSON object")

    materials = {}
    for key, spec in reader.get(data, "materials", "", {}, dict).items():
        field = f"materials.{key}"
        if not isinstance(spec, dict):
            reader.fail(field, "must be an object")
        materials[key] = Material(
            name=key,
            albedo=reader.vector(spec, "albedo", field, [0.8, 0.8, 0.8], nonnegative=True),
            roughness=reader.number(spec, "roughness", field, 1.0, minimum=0.0, maximum=1.0),
            metalness=reader.number(spec, "metalness", field, 0.0, minimum=0.0, maximum=1.0),
            specular=reader.number(spec, "specular", field, 0.0, minimum=0.0, maximum=1.0),
            emission=reader.vector(spec, "emission", field, [0.0, 0.0, 0.0], nonnegative=True,
                                   maximum=MATERIAL_RANGES["emission"][1]),
            double_sided=reader.get(spec, "double_sided", field, False, bool),
        )
        if np.any(materials[key].albedo > 1.0):
            reader.fail(f"{field}.albedo", "must be at most 1 per channel (energy conservation)")
        check_material(materials[key], reader.fail, {name: f"{field}.{name}" for name in MATERIAL_RANGES})

    camera_spec = reader.get(data, "camera", "", kind=dict)
    camera = Camera(
        position=reader.vector(camera_spec, "position", "camera"),
        look_at=reader.vector(camera_spec, "look_at", "camera"),
        up=reader.vector(camera_spec, "up", "camera", [0.0, 1.0, 0.0]),
        vertical_fov_deg=reader.number(camera_spec, "vertical_fov_deg", "camera", 60.0, minimum=MIN_FOV_DEG, maximum=179.0),
        width=int(reader.number(camera_spec, "width", "camera", 256, positive=True, whole=True)),
        height=int(reader.number(camera_spec, "height", "camera", 256, positive=True, whole=True)),
    )
    forward = camera.look_at - camera.position
    if np.linalg.norm(forward) == 0:
        reader.fail("camera.look_at", "must differ from camera.position")
    if np.linalg.norm(np.cross(forward, camera.up)) < 1e-9 * np.linalg.norm(forward):
        reader.fail("camera.up", "must not be parallel to the viewing direction")

    name = reader.get(data, "name", "", path.stem, str)
    root = Node(name=_title(name))
    meshes = {}
    for i, spec in enumerate(reader.get(data, "objects", "", [], list)):
        root.children.append(_node(reader, spec, f"objects[{i}]", materials, meshes, inputs, np.eye(4), 1))
    for i, spec in enumerate(reader.get(data, "lights", "", [], list)):
        if not isinstance(spec, dict) or spec.get("type") not in LIGHT_TYPES:
            reader.fail(f"lights[{i}].type", f"must be one of {', '.join(LIGHT_TYPES)}")
        root.children.append(_node(reader, spec, f"lights[{i}]", materials, meshes, inputs, np.eye(4), 1))

    region = None
    if "voxel_region" in data:
        spec = reader.get(data, "voxel_region", "", kind=dict)
        region = VoxelRegion(reader.vector(spec, "center", "voxel_region"),
                             reader.number(spec, "size", "voxel_region", minimum=MIN_SCALE))
    return Scene(name=name, root=root, camera=camera, materials=materials, voxel_region=region, source=str(path),
                 files=tuple(inputs.paths))


def _title(name):
    return " ".join(word.capitalize() for word in name.replace("_", " ").split()) or "Scene"


def _node(reader, spec, field, materials, meshes, inputs, parent_world, depth):
    """The node of `spec` with its children; `parent_world` places it, `depth` counts the
    levels down to it (1: a top-level object or light)."""
    if not isinstance(spec, dict):
        reader.fail(field, "must be an object")
    if depth > MAX_DEPTH:
        reader.fail(field, f"children nest more than {MAX_DEPTH} levels deep")
    kind = reader.get(spec, "type", field, kind=str)
    name = reader.get(spec, "name", field, f"{kind} {field}", str)
    field = f'{field} "{name}"' if "name" in spec else field
    if kind not in GEOMETRY_TYPES + LIGHT_TYPES:
        reader.fail(f"{field}.type", f'unknown type "{kind}" (expected one of {", ".join(GEOMETRY_TYPES + LIGHT_TYPES)})')
    node = Node(
        name=name,
        translation=reader.vector(spec, "translation", field, [0.0, 0.0, 0.0]),
        rotation_deg=reader.vector(spec, "rotation", field, [0.0, 0.0, 0.0]),
        scale=reader.vector(spec, "scale", field, [1.0, 1.0, 1.0], positive=True),
    )
    file_nodes = []
    if kind in LIGHT_TYPES:
        node.light = _light(reader, spec, field, kind)
    elif kind != "group":
        if kind != "mesh" or "material" in spec:  # a mesh file without one has its own materials
            material_name = reader.get(spec, "material", field, kind=str)
            if material_name not in materials:
                reader.fail(f"{field}.material", f'unknown material "{material_name}"')
            node.material = materials[material_name]
        if kind == "mesh":
            file_nodes = _load_mesh_file(reader, spec, field, node, meshes, inputs)
        else:
            node.mesh = _mesh(reader, spec, field, kind, node, meshes)
    world = parent_world @ node.local_matrix()
    check_placement(node, world, _placement_failure(reader, field))
    for part in file_nodes:
        _check_file_nodes(reader, part, world, depth + 1, f"{field}.file: {spec['file']}")
    for i, child in enumerate(reader.get(spec, "children", field, [], list)):
        node.children.append(_node(reader, child, f"{field}.children[{i}]", materials, meshes, inputs, world, depth + 1))
    return node


def _placement_failure(reader, field):
    """check_placement's `fail` for the node at `field`."""
    return lambda attribute, message: reader.fail(f"{field}.{attribute}" if attribute else field, message)


def _check_file_nodes(reader, top, parent_world, depth, where):
    """The limits of the scene's own nodes (engine.limits: depth, world transforms, reach)
    for the nodes a mesh file added below a node, `top` at `depth`; `where` names the file."""
    stack = [(top, parent_world, depth)]
    while stack:
        node, parent, level = stack.pop()
        field = f'{where}: node "{node.name}"'
        if level > MAX_DEPTH:
            reader.fail(field, f"nests more than {MAX_DEPTH} levels deep (the scene's levels above it counted in)")
        world = parent @ node.local_matrix()
        check_placement(node, world, _placement_failure(reader, field))
        stack.extend((child, world, level + 1) for child in reversed(node.children))


def _mesh(reader, spec, field, kind, node, meshes):
    """The mesh of a quad, box or sphere; boxes and spheres scale and place `node`."""
    if kind == "quad":
        vertices = reader.get(spec, "vertices", field, kind=list)
        if len(vertices) != 4:
            reader.fail(f"{field}.vertices", "must hold 4 vertices")
        v = np.array([reader.vector_value(p, f"{field}.vertices[{i}]") for i, p in enumerate(vertices)])
        a = np.cross(v[1] - v[0], v[2] - v[0])
        b = np.cross(v[2] - v[0], v[3] - v[0])
        scale = max(np.ptp(v, axis=0).max(), 1e-30) ** 2
        if np.linalg.norm(a) < 1e-9 * scale or np.linalg.norm(b) < 1e-9 * scale or np.dot(a, b) <= 0:
            reader.fail(f"{field}.vertices", "degenerate quad (zero area, collinear or folded vertices)")
        return quad_mesh(v)
    if kind == "box":
        if "center" in spec:
            node.translation = node.translation + reader.vector(spec, "center", field)
        if "rotation_y_deg" in spec:
            node.rotation_deg = node.rotation_deg + np.array([0.0, reader.number(spec, "rotation_y_deg", field), 0.0])
        node.scale = node.scale * reader.vector(spec, "size", field, positive=True)
        return meshes.setdefault("box", box_mesh())
    # sphere
    if "center" in spec:
        node.translation = node.translation + reader.vector(spec, "center", field)
    node.scale = node.scale * reader.number(spec, "radius", field, positive=True)
    return meshes.setdefault("sphere", sphere_mesh())


def _load_mesh_file(reader, spec, field, node, meshes, inputs):
    """The file's nodes under `node`, all with `node.material` where it has one; a file that
    is one part in its own frame (one OBJ material group, a PLY, a glTF node with one
    primitive) becomes `node`'s own mesh and material instead. A file is read once however
    many objects use it with the same material: they share its meshes and materials. Returns
    the nodes added under `node`."""
    relative = reader.get(spec, "file", field, kind=str)
    where = f"{field}.file"
    try:
        path = (reader.path.parent / relative).resolve()
    except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
        reader.fail(where, f'cannot read mesh "{relative}" ({os_problem(exc)})')
    key = (path, id(node.material))
    if key not in meshes:
        try:
            meshes[key] = load_mesh_file(path, relative, node.material, inputs)
        except SceneError as exc:
            reader.fail(where, str(exc))
    parts = [_copy_tree(part) for part in meshes[key]]
    if not any(n.mesh is not None for part in parts for n, _ in part.walk()):
        reader.fail(where, f'{relative}: holds no triangles')
    if len(parts) == 1 and not parts[0].children and np.array_equal(parts[0].local_matrix(), np.eye(4)):
        node.mesh, node.material = parts[0].mesh, parts[0].material
        return []
    node.children.extend(parts)
    return parts


def _copy_tree(node):
    """A copy of the nodes (their own transforms), sharing meshes, materials and lights."""
    copy = dataclasses.replace(node, translation=node.translation.copy(), rotation_deg=node.rotation_deg.copy(),
                               scale=node.scale.copy(), children=[])
    copy.children = [_copy_tree(child) for child in node.children]
    return copy


def _light(reader, spec, field, kind):
    light = Light(type=kind, intensity=reader.vector(spec, "intensity" if kind != "directional" else "irradiance", field, nonnegative=True))
    if kind in ("point", "spot"):
        light.position = reader.vector(spec, "position", field)
        light.range = reader.number(spec, "range", field, 0.0, minimum=0.0)
    if kind in ("spot", "directional"):
        direction = reader.vector(spec, "direction", field)
        if np.linalg.norm(direction) == 0:
            reader.fail(f"{field}.direction", "must not be zero")
        light.direction = direction / np.linalg.norm(direction)
    if kind == "spot":
        light.outer_angle_deg = reader.number(spec, "outer_angle_deg", field, 45.0, positive=True, maximum=89.0)
        light.inner_angle_deg = reader.number(spec, "inner_angle_deg", field, light.outer_angle_deg * 0.8, minimum=0.0, maximum=light.outer_angle_deg)
    light.cast_shadows = reader.get(spec, "cast_shadows", field, True, bool)
    return light
