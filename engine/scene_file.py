"""JSON scene files -> scene model. Every malformed value raises SceneError naming the
file and the field, e.g. `scenes/x.json: objects[6] "Short Box".size: must be positive`."""
import io
import json
import math
import os
import stat
from pathlib import Path

import numpy as np

from .errors import SceneError
from .scene import Camera, Light, Material, Node, Scene, VoxelRegion, box_mesh, quad_mesh, sphere_mesh, Mesh

GEOMETRY_TYPES = ("quad", "box", "sphere", "mesh", "group")
LIGHT_TYPES = ("point", "spot", "directional")

# Limits that keep what the GPU computes from a scene finite in float32 and its transforms
# invertible: every number within +-MAX_MAGNITUDE (metres, degrees, W/sr, W/m^2), world
# positions too, and every world transform scaling by MIN_SCALE..MAX_MAGNITUDE. Emission is
# held in half floats (the G-buffer): at most MAX_EMISSION.
MAX_MAGNITUDE = 1e6
MIN_SCALE = 1e-6
MAX_EMISSION = float(np.finfo(np.float16).max)  # 65504
MIN_FOV_DEG = 0.01
MAX_DEPTH = 32  # levels of nested children
# Files are read whole, up to these sizes (a device such as /dev/zero is not read at all).
MAX_SCENE_BYTES = 4 * 2 ** 20
MAX_MESH_BYTES = 256 * 2 ** 20


class _Reader:
    def __init__(self, path):
        self.path = Path(path)

    def fail(self, field, message):
        raise SceneError(message, source=self.path, field=field)

    def get(self, obj, key, field, default=..., kind=None):
        if key not in obj:
            if default is ...:
                self.fail(f"{field}.{key}" if field else key, "missing")
            return default
        value = obj[key]
        if kind is not None and not isinstance(value, kind):
            self.fail(f"{field}.{key}" if field else key, f"must be {_kind_name(kind)}")
        return value

    def number(self, obj, key, field, default=..., positive=False, minimum=None, maximum=MAX_MAGNITUDE, whole=False):
        value = self.get(obj, key, field, default)
        where = f"{field}.{key}" if field else key
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(where, "must be a number")
        if not _finite(value):
            self.fail(where, "must be finite")
        if whole and value != int(value):
            self.fail(where, "must be a whole number")
        if positive and value <= 0:
            self.fail(where, "must be positive")
        if minimum is not None and value < minimum:
            self.fail(where, f"must be at least {minimum:g}")
        if value > maximum:
            self.fail(where, f"must be at most {maximum:g}")
        if value < -MAX_MAGNITUDE:
            self.fail(where, f"must be at least {-MAX_MAGNITUDE:g}")
        return float(value)

    def vector(self, obj, key, field, default=..., length=3, positive=False, nonnegative=False, maximum=MAX_MAGNITUDE):
        value = self.get(obj, key, field, default)
        if value is default and default is not ...:
            return np.array(default, float)
        return self.vector_value(value, f"{field}.{key}" if field else key, length, positive, nonnegative, maximum)

    def vector_value(self, value, where, length=3, positive=False, nonnegative=False, maximum=MAX_MAGNITUDE):
        if not isinstance(value, list) or len(value) != length:
            self.fail(where, f"must be a list of {length} numbers")
        for i, v in enumerate(value):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or v is None:
                self.fail(f"{where}[{i}]", "must be a number")
            if not _finite(v):
                self.fail(f"{where}[{i}]", "must be finite (got NaN, infinity or an out-of-range number)")
            if positive and v <= 0:
                self.fail(f"{where}[{i}]", "must be positive")
            if nonnegative and v < 0:
                self.fail(f"{where}[{i}]", "must not be negative")
            if v > maximum:
                self.fail(f"{where}[{i}]", f"must be at most {maximum:g}")
            if v < -MAX_MAGNITUDE:
                self.fail(f"{where}[{i}]", f"must be at least {-MAX_MAGNITUDE:g}")
        return np.array(value, float)


def _kind_name(kind):
    names = {dict: "an object", list: "a list", str: "a string", bool: "true or false"}
    return names.get(kind, kind.__name__ if isinstance(kind, type) else "valid")


def _finite(value):
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer too large for a float
        return False


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


def read_regular_file(path, limit):
    """The bytes of `path`, which must be a regular file of at most `limit` bytes: never reads
    a device such as /dev/zero, nor blocks on a pipe. Raises OSError saying what is wrong."""
    descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(descriptor, "rb") as f:
        if not stat.S_ISREG(os.fstat(descriptor).st_mode):
            raise OSError("not a regular file")
        data = f.read(limit + 1)
    if len(data) > limit:
        raise OSError(f"larger than {limit // 2 ** 20} MiB")
    return data


def load_scene(path):
    """Load a JSON scene file into a Scene (pure Python/numpy, no GL)."""
    path = Path(path)
    reader = _Reader(path)
    try:
        text = read_regular_file(path, MAX_SCENE_BYTES).decode("utf-8")
    except OSError as exc:
        raise SceneError(f"cannot read scene file ({exc.strerror or exc})", source=path) from None
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
            emission=reader.vector(spec, "emission", field, [0.0, 0.0, 0.0], nonnegative=True, maximum=MAX_EMISSION),
        )
        if np.any(materials[key].albedo > 1.0):
            reader.fail(f"{field}.albedo", "must be at most 1 per channel (energy conservation)")

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
        root.children.append(_node(reader, spec, f"objects[{i}]", materials, meshes, np.eye(4), 1))
    for i, spec in enumerate(reader.get(data, "lights", "", [], list)):
        if not isinstance(spec, dict) or spec.get("type") not in LIGHT_TYPES:
            reader.fail(f"lights[{i}].type", f"must be one of {', '.join(LIGHT_TYPES)}")
        root.children.append(_node(reader, spec, f"lights[{i}]", materials, meshes, np.eye(4), 1))

    region = None
    if "voxel_region" in data:
        spec = reader.get(data, "voxel_region", "", kind=dict)
        region = VoxelRegion(reader.vector(spec, "center", "voxel_region"),
                             reader.number(spec, "size", "voxel_region", minimum=MIN_SCALE))
    return Scene(name=name, root=root, camera=camera, materials=materials, voxel_region=region, source=str(path))


def _title(name):
    return " ".join(word.capitalize() for word in name.replace("_", " ").split()) or "Scene"


def _node(reader, spec, field, materials, meshes, parent_world, depth):
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
    if kind in LIGHT_TYPES:
        node.light = _light(reader, spec, field, kind)
    elif kind != "group":
        material_name = reader.get(spec, "material", field, kind=str)
        if material_name not in materials:
            reader.fail(f"{field}.material", f'unknown material "{material_name}"')
        node.material = materials[material_name]
        node.mesh = _mesh(reader, spec, field, kind, node, meshes)
    world = parent_world @ node.local_matrix()
    _check_placement(reader, node, world, field)
    for i, child in enumerate(reader.get(spec, "children", field, [], list)):
        node.children.append(_node(reader, child, f"{field}.children[{i}]", materials, meshes, world, depth + 1))
    return node


def _check_placement(reader, node, world, field):
    """The node's world transform must be invertible within float32, and what it places (the
    mesh, the light) must lie within +-MAX_MAGNITUDE of the origin."""
    scales = np.linalg.svd(world[:3, :3], compute_uv=False)
    if not MIN_SCALE <= scales.min() <= scales.max() <= MAX_MAGNITUDE:
        reader.fail(f"{field}.scale", f"its world transform (its parents', its own, its size) scales by {scales.min():.3g}.."
                                      f"{scales.max():.3g}; each must be within {MIN_SCALE:g}..{MAX_MAGNITUDE:g}")
    if node.mesh is not None:
        lo, hi = node.mesh.bounds(world)
        reach, where = max(np.abs(lo).max(), np.abs(hi).max()), field
    elif node.light is not None:
        position = world[:3, :3] @ node.light.position + world[:3, 3]
        reach, where = np.abs(position).max(), f"{field}.position"
    else:
        reach, where = np.abs(world[:3, 3]).max(), f"{field}.translation"
    if reach > MAX_MAGNITUDE:
        reader.fail(where, f"reaches {reach:.3g} m from the origin along an axis in the world, beyond {MAX_MAGNITUDE:g}")


def _mesh(reader, spec, field, kind, node, meshes):
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
    if kind == "sphere":
        if "center" in spec:
            node.translation = node.translation + reader.vector(spec, "center", field)
        node.scale = node.scale * reader.number(spec, "radius", field, positive=True)
        return meshes.setdefault("sphere", sphere_mesh())
    return _load_mesh_file(reader, spec, field, meshes)


def _load_mesh_file(reader, spec, field, meshes):
    """A mesh file, read once however many objects use it. Its materials are not used (the
    object's material is), so an OBJ file's `usemtl`/`mtllib` lines are dropped before parsing:
    trimesh makes a mesh per material and names them in quadratic time."""
    import trimesh

    relative = reader.get(spec, "file", field, kind=str)
    where = f"{field}.file"
    try:
        path = (reader.path.parent / relative).resolve()
        if path in meshes:
            return meshes[path]
        data = read_regular_file(path, MAX_MESH_BYTES)
    except FileNotFoundError:
        reader.fail(where, f'mesh file not found: "{relative}"')
    except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
        reader.fail(where, f'cannot read mesh "{relative}" ({getattr(exc, "strerror", None) or exc})')
    file_type = path.suffix.lstrip(".").lower()
    if file_type == "obj":
        lines = data.decode("utf-8", errors="replace").splitlines()
        data = "\n".join(line for line in lines if line.split(maxsplit=1)[:1] not in (["usemtl"], ["mtllib"])).encode()
    try:
        mesh = trimesh.load(io.BytesIO(data), file_type=file_type, force="mesh", process=True,
                            resolver=trimesh.resolvers.FilePathResolver(str(path)))
    except ImportError:  # trimesh guesses the encoding of text that is not UTF-8 with an optional module
        reader.fail(where, f'cannot load mesh "{relative}": neither a binary {file_type.upper()} file nor UTF-8 text')
    except Exception as exc:  # trimesh raises many kinds on unreadable files
        reader.fail(where, f'cannot load mesh "{relative}": {" ".join(str(exc).split()) or type(exc).__name__}')
    if isinstance(mesh, trimesh.Trimesh):
        mesh.update_faces(mesh.nondegenerate_faces())
        mesh.remove_unreferenced_vertices()
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        reader.fail(where, f'mesh "{relative}" holds no triangles')
    meshes[path] = _smooth_mesh(np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64))
    return meshes[path]


def _smooth_mesh(positions, indices):
    """A Mesh with area-weighted vertex normals (numpy only: trimesh's own path needs scipy and
    prints a traceback without it); flat normals where faces facing apart share a vertex."""
    corners = positions[indices]
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])  # length: 2 x area
    face_areas = np.linalg.norm(face_normals, axis=1, keepdims=True)
    normals, areas = np.zeros_like(positions), np.zeros((len(positions), 1))
    np.add.at(normals, indices.ravel(), np.repeat(face_normals, 3, axis=0))
    np.add.at(areas, indices.ravel(), np.repeat(face_areas, 3, axis=0))
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    if np.all(lengths > 1e-6 * areas):
        return Mesh(positions, normals / lengths, indices)
    flat = np.repeat(face_normals / face_areas, 3, axis=0)
    return Mesh(corners.reshape(-1, 3), flat, np.arange(3 * len(indices)).reshape(-1, 3))


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
