"""JSON scene files -> scene model. Every malformed value raises SceneError naming the
file and the field, e.g. `scenes/x.json: objects[6] "Short Box".size: must be positive`."""
import json
from pathlib import Path

import numpy as np

from .errors import SceneError
from .json_reader import JsonReader
from .mesh_files import load_mesh_file
from .scene import Camera, Light, Material, Node, Scene, VoxelRegion, box_mesh, quad_mesh, sphere_mesh

GEOMETRY_TYPES = ("quad", "box", "sphere", "mesh", "group")
LIGHT_TYPES = ("point", "spot", "directional")


class _Constant:
    """A NaN/Infinity token (Python's json accepts them; JSON does not): kept in place while
    parsing so the loader can name the field it stood in."""

    def __init__(self, text):
        self.text = text


def _find_constant(value, where=""):
    """(field, token) of the first NaN/Infinity token in the parsed document, or None."""
    if isinstance(value, _Constant):
        return where, value.text
    if isinstance(value, dict):
        items = ((f"{where}.{key}" if where else key, item) for key, item in value.items())
    elif isinstance(value, list):
        items = ((f"{where}[{i}]", item) for i, item in enumerate(value))
    else:
        return None
    for field, item in items:
        found = _find_constant(item, field)
        if found:
            return found
    return None


def load_scene(path):
    """Load a JSON scene file into a Scene (pure Python/numpy, no GL)."""
    path = Path(path)
    reader = JsonReader(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(f"cannot read scene file ({exc.strerror or exc})", source=path) from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"not UTF-8 text (byte {exc.start})", source=path) from None
    try:
        data = json.loads(text, parse_constant=_Constant)
    except json.JSONDecodeError as exc:
        raise SceneError(f"malformed JSON: {exc.msg}", source=path, field=f"line {exc.lineno} column {exc.colno}") from None
    except ValueError as exc:
        raise SceneError(f"malformed JSON: {exc}", source=path) from None
    except RecursionError:
        raise SceneError("malformed JSON: nested too deeply", source=path) from None
    constant = _find_constant(data)
    if constant:
        reader.fail(constant[0], f"malformed JSON: {constant[1]} is not a JSON number (JSON has no NaN or Infinity)")
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
            emission=reader.vector(spec, "emission", field, [0.0, 0.0, 0.0], nonnegative=True),
        )
        if np.any(materials[key].albedo > 1.0):
            reader.fail(f"{field}.albedo", "must be at most 1 per channel (energy conservation)")

    camera_spec = reader.get(data, "camera", "", kind=dict)
    camera = Camera(
        position=reader.vector(camera_spec, "position", "camera"),
        look_at=reader.vector(camera_spec, "look_at", "camera"),
        up=reader.vector(camera_spec, "up", "camera", [0.0, 1.0, 0.0]),
        vertical_fov_deg=reader.number(camera_spec, "vertical_fov_deg", "camera", 60.0, positive=True, maximum=179.0),
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
        root.children.append(_node(reader, spec, f"objects[{i}]", materials, meshes))
    for i, spec in enumerate(reader.get(data, "lights", "", [], list)):
        if not isinstance(spec, dict) or spec.get("type") not in LIGHT_TYPES:
            reader.fail(f"lights[{i}].type", f"must be one of {', '.join(LIGHT_TYPES)}")
        root.children.append(_node(reader, spec, f"lights[{i}]", materials, meshes))

    region = None
    if "voxel_region" in data:
        spec = reader.get(data, "voxel_region", "", kind=dict)
        region = VoxelRegion(reader.vector(spec, "center", "voxel_region"),
                             reader.number(spec, "size", "voxel_region", positive=True))
    return Scene(name=name, root=root, camera=camera, materials=materials, voxel_region=region, source=str(path))


def _title(name):
    return " ".join(word.capitalize() for word in name.replace("_", " ").split()) or "Scene"


def _node(reader, spec, field, materials, meshes):
    if not isinstance(spec, dict):
        reader.fail(field, "must be an object")
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
    if kind in LIGHT_TYPES:
        node.light = _light(reader, spec, field, kind)
    elif kind != "group":
        if kind != "mesh" or "material" in spec:  # a mesh file without one has its own materials
            material_name = reader.get(spec, "material", field, kind=str)
            if material_name not in materials:
                reader.fail(f"{field}.material", f'unknown material "{material_name}"')
            node.material = materials[material_name]
        if kind == "mesh":
            _load_mesh_file(reader, spec, field, node)
        else:
            node.mesh = _mesh(reader, spec, field, kind, node, meshes)
    for i, child in enumerate(reader.get(spec, "children", field, [], list)):
        node.children.append(_node(reader, child, f"{field}.children[{i}]", materials, meshes))
    return node


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


def _load_mesh_file(reader, spec, field, node):
    """The file's nodes under `node`, all with `node.material` where it has one; a file that
    is one part in its own frame (one OBJ material group, a PLY, a glTF node with one
    primitive) becomes `node`'s own mesh and material instead."""
    relative = reader.get(spec, "file", field, kind=str)
    path = (reader.path.parent / relative).resolve()
    if not path.is_file():
        reader.fail(f"{field}.file", f'mesh file not found: "{relative}"')
    try:
        parts = load_mesh_file(path, relative, node.material)
    except SceneError as exc:
        reader.fail(f"{field}.file", str(exc))
    if not any(n.mesh is not None for part in parts for n, _ in part.walk()):
        reader.fail(f"{field}.file", f'{relative}: holds no triangles')
    if len(parts) == 1 and not parts[0].children and np.array_equal(parts[0].local_matrix(), np.eye(4)):
        node.mesh, node.material = parts[0].mesh, parts[0].material
    else:
        node.children.extend(parts)


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
