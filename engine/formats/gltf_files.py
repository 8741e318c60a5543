"""glTF 2.0 files -> scene-graph nodes with meshes, materials, textures, cameras, lights and
animations (plain Python/numpy, no GL); engine/formats/mesh_files.py's load_mesh_file reads them here.

From a .gltf file (with its buffers and images) or a .glb: the default scene's node hierarchy
(names; translation/rotation/scale or a matrix), one child node per primitive where a mesh has
several, each with its material (the mapping is in engine.scene.model.Material's docstring). NORMAL,
TEXCOORD_0, TEXCOORD_1, TANGENT and COLOR_0 come from the file; a primitive without NORMAL
gets flat normals (as the glTF spec says), one whose material has a normal texture but no
TANGENT gets tangents from its texture coordinates (Lengyel's per-triangle derivatives,
summed per vertex). Triangle lists, strips and fans; sparse accessors; data URIs and
external files. Cameras become NodeCameras of their nodes (perspective yfov and aspectRatio,
orthographic xmag/ymag; the node's -z is the view direction, +y up); KHR_lights_punctual
lights become Lights of their nodes (at the node's origin, shining along its -z): colour x
intensity, point and spot in candela, directional in lux, over LUMENS_PER_WATT = 683 into
W/sr and W/m^2; range; a spot's innerConeAngle and outerConeAngle (radians) as its inner and
outer angles. Animations: each channel that moves a node's translation, rotation or scale
(LINEAR, STEP, CUBICSPLINE) becomes a Sampler of the node's NodeTracks (engine.scene.animation),
under the animation's name ("animation N" where it has none); skins and morph targets are
not played (the rest pose is drawn, with one warning). Extensions the file uses without
requiring them and vct does not read are left out, as glTF allows, with one warning naming
them.

Images are decoded once per file: materials that use the same image (by content) the same way
share one Texture object. Primitives without a material get a grey Lambertian default (albedo
0.8, like a scene material with no fields). The file, its buffers and its images are read
through the scene's InputFiles (engine/formats/input_files.py), and what the file holds is held to
engine/core/limits.py: vertex data finite and within +-1e6, materials within their ranges, nodes
nested at most MAX_DEPTH levels. Bad input raises SceneError naming the file and the element,
e.g. `sponza.glb: materials[3].pbrMetallicRoughness.baseColorTexture: images[5] "bricks.png":
file not found`.
"""
import base64
import json
import math
import struct
import urllib.parse
from collections import namedtuple
from pathlib import Path

import numpy as np

from ..core.errors import warn
from ..core.limits import MAX_DEPTH, MAX_FILE_BYTES, MAX_MAGNITUDE, MIN_FOV_DEG, MIN_SCALE, check_material, check_vertices
from ..core.progress import progress
from ..core.transforms import decompose, euler_deg_from_rotation, quaternion_rotation
from ..scene.animation import INTERPOLATIONS, PATHS, NodeTracks, Sampler
from ..scene.model import ALPHA_MODES, IDENTITY_UV, TEXTURE_FIELDS, Light, Material, Mesh, Node, NodeCamera
from .input_files import os_problem
from .json_reader import JsonReader
from .mesh_building import FileTextures, default_material, face_normals, flat_normals, generate_tangents

# The extensions this reader understands; others a file uses are left out, with a warning.
GLTF_EXTENSIONS = ("KHR_materials_emissive_strength", "KHR_lights_punctual", "KHR_texture_transform")
LUMENS_PER_WATT = 683.0  # photometric to radiometric units at 555 nm: W/sr = cd / 683, W/m^2 = lux / 683
MAX_SPOT_ANGLE_DEG = 89.0  # a spot light's shadow is one perspective view of twice its outer angle

COMPONENT_TYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
FLOAT = (5126,)
INDEX_TYPES = (5121, 5123, 5125)
NORMALIZED_UV_TYPES = (5121, 5123)
NORMALIZED_ROTATION_TYPES = (5120, 5121, 5122, 5123)  # animation rotations may be signed too
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
GLTF_WRAP_MODES = {10497: "REPEAT", 33071: "CLAMP_TO_EDGE", 33648: "MIRRORED_REPEAT"}
MODE_NAMES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP"}
GLB_JSON, GLB_BIN = 0x4E4F534A, 0x004E4942


class GltfFile:
    """One glTF file: its document, buffers, and what was built from it (meshes, materials and
    textures, each once)."""

    def __init__(self, path, data, name, material, inputs):
        self.path = Path(path)
        self.json = JsonReader(name)
        self.override = material
        self.inputs = inputs
        self.glb_bin = None
        self.doc = self._document(data)
        self.buffers = {}
        self.meshes = {}
        self.materials = {}
        self.default = default_material()
        self.textures = FileTextures(inputs)
        self.placed = set()  # the nodes placed in the hierarchy so far
        self.node_objects = {}  # node index -> the Node made of it
        required = self.json.get(self.doc, "extensionsRequired", "", [], list)
        missing = [str(e) for e in required if e not in GLTF_EXTENSIONS]
        if missing:
            self.json.fail("extensionsRequired", f"needs {', '.join(missing)}, which vct does not read "
                                                 f"(it reads {', '.join(GLTF_EXTENSIONS)})")
        unread = sorted({str(e) for e in self.json.get(self.doc, "extensionsUsed", "", [], list)} - set(GLTF_EXTENSIONS))
        if unread:
            warn(f"uses extensions vct does not read, drawn without them: {', '.join(unread)}", source=name)

    def fail(self, field, message):
        self.json.fail(field, message)

    def list(self, key):
        return self.json.get(self.doc, key, "", [], list)

    def element(self, key, index):
        value = self.list(key)[index]
        if not isinstance(value, dict):
            self.fail(f"{key}[{index}]", "must be an object")
        return value

    # -- container

    def _document(self, data):
        text = data
        if data[:4] == b"glTF":
            text = self._glb_chunks(data)
        try:
            doc = json.loads(text)
        except (ValueError, RecursionError) as exc:
            self.fail("", f"malformed JSON ({exc})")
        if not isinstance(doc, dict):
            self.fail("", "the glTF JSON must be an object")
        version = str(self.json.get(self.json.get(doc, "asset", "", kind=dict), "version", "asset"))
        if not version.startswith("2."):
            self.fail("asset.version", f"glTF {version}: only glTF 2.0 is read")
        return doc

    def _glb_chunks(self, data):
        """The JSON chunk of a GLB file; keeps the BIN chunk for buffers[0]."""
        if len(data) < 20:
            self.fail("GLB header", "file too short")
        _, version, length = struct.unpack_from("<4sII", data)
        if version != 2:
            self.fail("GLB header", f"GLB version {version}: only version 2 is read")
        if length > len(data):
            self.fail("GLB header", f"says {length} bytes, the file has {len(data)}")
        chunks, offset = [], 12
        while offset + 8 <= length:
            size, kind = struct.unpack_from("<II", data, offset)
            if offset + 8 + size > length:
                self.fail(f"GLB chunk {len(chunks)}", "reaches past the end of the file")
            chunks.append((kind, data[offset + 8:offset + 8 + size]))
            offset += 8 + size + (-size % 4)
        if not chunks or chunks[0][0] != GLB_JSON:
            self.fail("GLB chunk 0", "must be the JSON chunk")
        if len(chunks) > 1 and chunks[1][0] == GLB_BIN:
            self.glb_bin = chunks[1][1]
        return chunks[0][1]

    def _uri_bytes(self, uri):
        """Bytes of a data URI or of a file relative to the glTF file; ValueError says why not."""
        if uri.startswith("data:"):
            header, _, payload = uri.partition(",")
            try:
                return base64.b64decode(payload, validate=True) if header.endswith(";base64") else urllib.parse.unquote_to_bytes(payload)
            except ValueError as exc:
                raise ValueError(f"malformed data URI ({exc})") from None
        try:
            return self.inputs.read(self.path.parent / urllib.parse.unquote(uri))
        except FileNotFoundError:
            raise ValueError("file not found") from None
        except (OSError, ValueError) as exc:
            raise ValueError(f"cannot read ({os_problem(exc)})") from None

    def buffer(self, index):
        if index not in self.buffers:
            field = f"buffers[{index}]"
            spec = self.element("buffers", index)
            length = int(self.json.number(spec, "byteLength", field, whole=True, minimum=1, maximum=MAX_FILE_BYTES))
            if "uri" in spec:
                uri = self.json.get(spec, "uri", field, kind=str)
                try:
                    data = self._uri_bytes(uri)
                except ValueError as exc:
                    self.fail(f"{field}.uri", f'"{_short(uri)}": {exc}')
            elif index == 0 and self.glb_bin is not None:
                data = self.glb_bin
            else:
                self.fail(field, "has no uri and is not the GLB's binary chunk")
            if len(data) < length:
                self.fail(field, f"holds {len(data)} bytes, byteLength says {length}")
            self.buffers[index] = data
        return self.buffers[index]

    def view_bytes(self, index):
        """(bytes of the buffer, offset, length, byteStride or None) of bufferViews[index]."""
        field = f"bufferViews[{index}]"
        view = self.element("bufferViews", index)
        data = self.buffer(self.json.index(view, "buffer", field, "buffers", len(self.list("buffers"))))
        offset = int(self.json.number(view, "byteOffset", field, 0, whole=True, minimum=0, maximum=MAX_FILE_BYTES))
        length = int(self.json.number(view, "byteLength", field, whole=True, minimum=1, maximum=MAX_FILE_BYTES))
        if offset + length > len(data):
            self.fail(field, "reaches past the end of its buffer")
        stride = view.get("byteStride")
        if stride is not None:
            stride = int(self.json.number(view, "byteStride", field, whole=True, minimum=4, maximum=252))
        return data, offset, length, stride

    # -- accessors

    def accessor(self, obj, key, field, types, components, as_float=True):
        """The accessor that obj[key] names, as a (count, width) array: float32 (integer
        components must then be normalized), each component finite and within +-1e6 (limits:
        check_vertices), else of its integer type (indices)."""
        index = self.json.index(obj, key, field, "accessors", len(self.list("accessors")))
        where = f"accessors[{index}]"
        spec = self.element("accessors", index)
        kind = self.json.get(spec, "type", where, kind=str)
        if kind not in types:
            self.fail(f"{where}.type", f"is {kind}; {field}.{key} must be {' or '.join(types)}")
        component = self.json.get(spec, "componentType", where, kind=int)
        if component not in components:
            self.fail(f"{where}.componentType", f"is {component}; {field}.{key} must be one of {components}")
        dtype = np.dtype(COMPONENT_TYPES[component]).newbyteorder("<")
        width = WIDTHS[kind]
        element = dtype.itemsize * width
        count = int(self.json.number(spec, "count", where, whole=True, minimum=1, maximum=math.inf))
        if count * element > MAX_FILE_BYTES:
            self.fail(f"{where}.count", f"{count} elements of {element} bytes: more than the {MAX_FILE_BYTES // 2 ** 20} MiB "
                                        "a buffer may hold")
        if "bufferView" in spec:
            values = self.view_array(spec, where, count, width, dtype, strided=True)
        else:
            values = np.zeros((count, width), dtype)
        if "sparse" in spec:
            self.apply_sparse(spec, where, values)
        normalized = as_float and dtype.kind != "f"
        if self.json.get(spec, "normalized", where, False, bool) != normalized:
            self.fail(f"{where}.normalized", f"must be {str(normalized).lower()} for {field}.{key} of componentType {component}")
        if normalized:
            return np.maximum(values / np.iinfo(dtype).max, -1.0).astype(np.float32)
        if as_float:
            check_vertices(values, lambda message: self.fail(where, f"({field}.{key}) {message}"))
        return values

    def view_array(self, spec, where, count, width, dtype, strided=False):
        view = self.json.index(spec, "bufferView", where, "bufferViews", len(self.list("bufferViews")))
        data, view_offset, view_length, stride = self.view_bytes(view)
        offset = int(self.json.number(spec, "byteOffset", where, 0, whole=True, minimum=0, maximum=MAX_FILE_BYTES))
        element = dtype.itemsize * width
        stride = stride if strided and stride else element
        if stride < element:
            self.fail(f"bufferViews[{view}].byteStride", f"{stride} bytes, less than the {element} of an element of {where}")
        if offset + stride * (count - 1) + element > view_length:
            self.fail(where, f"{count} elements reach past the end of bufferViews[{view}]")
        return np.array(np.ndarray((count, width), dtype, buffer=data, offset=view_offset + offset,
                                   strides=(stride, dtype.itemsize)))

    def apply_sparse(self, spec, where, values):
        field = f"{where}.sparse"
        sparse = self.json.get(spec, "sparse", where, kind=dict)
        count = int(self.json.number(sparse, "count", field, whole=True, minimum=1, maximum=len(values)))
        indices_spec = self.json.get(sparse, "indices", field, kind=dict)
        component = self.json.get(indices_spec, "componentType", f"{field}.indices", kind=int)
        if component not in INDEX_TYPES:
            self.fail(f"{field}.indices.componentType", f"must be one of {INDEX_TYPES}")
        indices = self.view_array(indices_spec, f"{field}.indices", count, 1, np.dtype(COMPONENT_TYPES[component]).newbyteorder("<"))
        if indices.max() >= len(values):
            self.fail(f"{field}.indices", f"refers to element {int(indices.max())} of {len(values)}")
        values_spec = self.json.get(sparse, "values", field, kind=dict)
        values[indices[:, 0]] = self.view_array(values_spec, f"{field}.values", count, values.shape[1], values.dtype)

    # -- nodes and meshes

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
        self.animate()
        self.buffers.clear()
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
            elif parts:
                node.children += [Node(name=f"{node.name}: {material.name}", mesh=mesh, material=material)
                                  for mesh, material in parts]
        self.placing.update()
        children = self.json.get(spec, "children", field, [], list)
        for k, child in enumerate(children):
            child = self.json.index_value(child, f"{field}.children[{k}]", "nodes", len(self.list("nodes")))
            node.children.append(self.node(child, depth + 1))
        return node

    # -- animations

    def animate(self):
        """Give the placed nodes that the file's animations move their NodeTracks. Skins and
        morph targets are not played: a file that has them is drawn in its rest pose, with one
        warning."""
        tracks = {}  # node index -> {animation name: {path: Sampler}}
        morphs = False
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
                if path == "weights":
                    morphs = True
                    continue
                if path not in PATHS:
                    self.fail(f"{where}.target.path", f'must be "translation", "rotation", "scale" or "weights", got "{path}"')
                if "node" not in target:  # glTF: a channel without a node is left to extensions
                    continue
                node = self.json.index(target, "node", f"{where}.target", "nodes", len(self.list("nodes")))
                s = self.json.index(channel, "sampler", where, f"{field}.samplers", len(samplers))
                sampler = self.sampler(samplers[s], f"{field}.samplers[{s}]", path)
                if node in self.node_objects:  # a node of another scene of the file is not drawn
                    tracks.setdefault(node, {}).setdefault(name, {})[path] = sampler
        for index, by_name in tracks.items():
            node = self.node_objects[index]
            node.animation = NodeTracks((node.translation.copy(), node.rotation_deg.copy(), node.scale.copy()), by_name)
        morphs = morphs or any("targets" in primitive for m in range(len(self.list("meshes")))
                               for primitive in self.json.get(self.element("meshes", m), "primitives", "", [], list)
                               if isinstance(primitive, dict))
        if self.list("skins") or morphs:
            kinds = " and ".join(k for k, present in (("skins", self.list("skins")), ("morph targets", morphs)) if present)
            warn(f"has {kinds}, which vct does not play: drawn in the rest pose", source=self.json.path)

    def sampler(self, spec, field, path):
        """The Sampler of an animation sampler that moves a node's `path`: input times strictly
        increasing, outputs one per time (three with CUBICSPLINE), each within the limits of a
        node's translation, unit rotation or scale."""
        if not isinstance(spec, dict):
            self.fail(field, "must be an object")
        interpolation = self.json.get(spec, "interpolation", field, "LINEAR", str)
        if interpolation not in INTERPOLATIONS:
            self.fail(f"{field}.interpolation", f'must be one of {", ".join(INTERPOLATIONS)}, got "{interpolation}"')
        times = self.accessor(spec, "input", field, ("SCALAR",), FLOAT)[:, 0].astype(np.float64)
        if np.any(times < 0) or np.any(np.diff(times) <= 0):
            self.fail(f"{field}.input", "times must be non-negative and strictly increasing")
        values = self.accessor(spec, "output", field, ("VEC4",) if path == "rotation" else ("VEC3",),
                               FLOAT + (NORMALIZED_ROTATION_TYPES if path == "rotation" else ())).astype(np.float64)
        per_time = 3 if interpolation == "CUBICSPLINE" else 1
        if len(values) != per_time * len(times):
            self.fail(f"{field}.output", f"has {len(values)} elements; {interpolation} over {len(times)} input times "
                                         f"needs {per_time * len(times)}")
        if path == "rotation":
            keyframes = values.reshape(len(times), per_time, 4)[:, per_time // 2]
            if not np.all((0.5 <= np.linalg.norm(keyframes, axis=1)) & (np.linalg.norm(keyframes, axis=1) <= 2.0)):
                self.fail(f"{field}.output", "rotations must be unit quaternions x, y, z, w")
        if path == "scale":
            scales = np.abs(values.reshape(len(times), per_time, 3)[:, per_time // 2])
            if np.any(scales < MIN_SCALE):
                self.fail(f"{field}.output", f"scales must be at least {MIN_SCALE:g} in magnitude")
        if per_time == 3:
            values = values.reshape(len(times), 3, -1)
        return Sampler(times, values, interpolation, rotation=path == "rotation")

    def camera(self, index):
        """The NodeCamera of cameras[index]: perspective (yfov in radians, aspectRatio) or
        orthographic (xmag, ymag: half the view's width and height)."""
        read, field = self.json, f"cameras[{index}]"
        spec = self.element("cameras", index)
        kind = read.get(spec, "type", field, kind=str)
        name = read.get(spec, "name", field, field, str)
        if kind == "perspective":
            where = f"{field}.perspective"
            lens = read.get(spec, "perspective", field, kind=dict)
            yfov = math.degrees(read.number(lens, "yfov", where, positive=True, maximum=math.radians(179.0)))
            if yfov < MIN_FOV_DEG:
                self.fail(f"{where}.yfov", f"must be at least {math.radians(MIN_FOV_DEG):g} (radians)")
            aspect = read.number(lens, "aspectRatio", where, None, positive=True) if "aspectRatio" in lens else None
            read.number(lens, "znear", where, positive=True)
            return NodeCamera(name=name, vertical_fov_deg=yfov, aspect_ratio=aspect)
        if kind == "orthographic":
            where = f"{field}.orthographic"
            lens = read.get(spec, "orthographic", field, kind=dict)
            xmag, ymag = (read.number(lens, key, where, positive=True) for key in ("xmag", "ymag"))
            read.number(lens, "znear", where, minimum=0.0)
            return NodeCamera(name=name, projection="orthographic", half_height=ymag, aspect_ratio=xmag / ymag)
        self.fail(f"{field}.type", f'must be "perspective" or "orthographic", got "{kind}"')

    def punctual_lights(self):
        extensions = self.json.get(self.doc, "extensions", "", {}, dict)
        lights = self.json.get(extensions, "KHR_lights_punctual", "extensions", {}, dict)
        return self.json.get(lights, "lights", "extensions.KHR_lights_punctual", [], list)

    def light(self, index):
        """The Light of KHR_lights_punctual's lights[index], in the node's frame (at its origin,
        shining along -z): colour x intensity in candela (point, spot) or lux (directional),
        turned into W/sr and W/m^2 at LUMENS_PER_WATT; range; the spot's cone angles."""
        read, field = self.json, f"extensions.KHR_lights_punctual.lights[{index}]"
        spec = self.punctual_lights()[index]
        if not isinstance(spec, dict):
            self.fail(field, "must be an object")
        kind = read.get(spec, "type", field, kind=str)
        if kind not in ("point", "spot", "directional"):
            self.fail(f"{field}.type", f'must be "point", "spot" or "directional", got "{kind}"')
        color = read.vector(spec, "color", field, [1.0, 1.0, 1.0], nonnegative=True)
        intensity = read.number(spec, "intensity", field, 1.0, minimum=0.0, maximum=MAX_MAGNITUDE * LUMENS_PER_WATT)
        light = Light(type=kind, intensity=color * intensity / LUMENS_PER_WATT, direction=np.array([0.0, 0.0, -1.0]))
        if kind != "directional" and "range" in spec:
            light.range = read.number(spec, "range", field, positive=True)
        if kind == "spot":
            where = f"{field}.spot"
            cone = read.get(spec, "spot", field, {}, dict)
            outer = math.degrees(read.number(cone, "outerConeAngle", where, math.pi / 4, positive=True))
            inner = math.degrees(read.number(cone, "innerConeAngle", where, 0.0, minimum=0.0))
            if outer > MAX_SPOT_ANGLE_DEG:
                self.fail(f"{where}.outerConeAngle", f"must be at most {math.radians(MAX_SPOT_ANGLE_DEG):.4f} (radians: "
                                                    f"{MAX_SPOT_ANGLE_DEG:g} degrees)")
            if inner >= outer:
                self.fail(f"{where}.innerConeAngle", "must be less than outerConeAngle")
            light.inner_angle_deg, light.outer_angle_deg = inner, outer
        return light

    def mesh(self, index):
        """[(Mesh, Material)] for the primitives of meshes[index] that hold a triangle of some
        area, made once."""
        if index not in self.meshes:
            field = f"meshes[{index}]"
            primitives = self.json.get(self.element("meshes", index), "primitives", field, kind=list)
            if not primitives:
                self.fail(f"{field}.primitives", "must not be empty")
            parts = [self.primitive(f"{field}.primitives[{k}]", p) for k, p in enumerate(primitives)]
            self.meshes[index] = [part for part in parts if part is not None]
        return self.meshes[index]

    def primitive(self, field, spec):
        """(Mesh, Material) of a primitive, its zero-area triangles dropped (they draw nothing and
        have no normal); None where none is left."""
        if not isinstance(spec, dict):
            self.fail(field, "must be an object")
        mode = int(self.json.number(spec, "mode", field, 4, whole=True, minimum=0, maximum=6))
        if mode in MODE_NAMES:
            self.fail(f"{field}.mode", f"{mode} ({MODE_NAMES[mode]}): only triangles are drawn (modes 4, 5, 6)")
        attributes = self.json.get(spec, "attributes", field, kind=dict)
        where = f"{field}.attributes"
        positions = self.accessor(attributes, "POSITION", where, ("VEC3",), FLOAT)
        optional = {"NORMAL": (("VEC3",), FLOAT), "TEXCOORD_0": (("VEC2",), FLOAT + NORMALIZED_UV_TYPES),
                    "TEXCOORD_1": (("VEC2",), FLOAT + NORMALIZED_UV_TYPES), "TANGENT": (("VEC4",), FLOAT),
                    "COLOR_0": (("VEC3", "VEC4"), FLOAT + NORMALIZED_UV_TYPES)}
        found = {}
        for key, (types, components) in optional.items():
            if key in attributes:
                found[key] = self.accessor(attributes, key, where, types, components)
                if len(found[key]) != len(positions):
                    self.fail(f"{where}.{key}", f"has {len(found[key])} elements, POSITION {len(positions)}")
        if "indices" in spec:
            indices = self.accessor(spec, "indices", field, ("SCALAR",), INDEX_TYPES, as_float=False)[:, 0].astype(np.uint32)
            if indices.max() >= len(positions):
                self.fail(f"{field}.indices", f"refers to vertex {int(indices.max())}, the primitive has {len(positions)}")
        else:
            indices = np.arange(len(positions), dtype=np.uint32)
        triangles = self.triangles(indices, mode, field)
        triangles = triangles[np.linalg.norm(face_normals(positions, triangles), axis=1) > 0]
        material = self.override or self.primitive_material(spec, field)
        normals, tangents = found.get("NORMAL"), found.get("TANGENT")
        texcoords, texcoords1 = found.get("TEXCOORD_0"), found.get("TEXCOORD_1")
        colors = found["COLOR_0"][:, :3] if "COLOR_0" in found else None
        if normals is not None:
            normals = self.unit_normals(normals, f"{where}.NORMAL", attributes["NORMAL"])
        for texture_field in (f for f in TEXTURE_FIELDS if getattr(material, f) is not None):
            uv_set = material.uv_sets.get(texture_field, 0)
            if (texcoords, texcoords1)[uv_set] is None:
                self.fail(field, f'material "{material.name}" has textures on TEXCOORD_{uv_set} but the primitive has no '
                                 f"TEXCOORD_{uv_set}")
        if normals is None:
            positions, normals, triangles, texcoords, tangents, colors, texcoords1 = flat_normals(
                positions, triangles, texcoords, tangents, colors, texcoords1)
        if material.normal_texture is not None and tangents is None:
            normal_uv = (texcoords, texcoords1)[material.uv_sets.get("normal_texture", 0)]
            tangents = generate_tangents(positions, normals, normal_uv, triangles)
        if len(triangles) == 0:
            return None
        return Mesh(positions, normals, triangles, texcoords, tangents, colors, texcoords1), material

    def unit_normals(self, normals, field, index):
        """The normals scaled to unit length (glTF requires unit normals; some files are off
        by rounding); a normal of (nearly) zero length gives no direction and is refused."""
        lengths = np.linalg.norm(normals.astype(np.float64), axis=1)
        if np.any(lengths < 1e-6):
            element = int(np.argmax(lengths < 1e-6))
            self.fail(f"accessors[{index}]", f"({field}) element {element} is {normals[element].tolist()}: "
                                             "a normal must have unit length")
        return (normals / lengths[:, None]).astype(np.float32)

    def triangles(self, indices, mode, field):
        if mode == 4:
            if len(indices) % 3:
                self.fail(field, f"{len(indices)} indices do not make whole triangles")
            triangles = indices.reshape(-1, 3)
        elif mode == 5:  # strip: every other triangle swaps two corners to keep the winding
            k = np.arange(max(len(indices) - 2, 0))
            odd = k % 2 == 1
            triangles = np.stack([indices[k + odd], indices[k + 1 - odd], indices[k + 2]], axis=1)
        else:  # fan
            k = np.arange(1, max(len(indices) - 1, 1))
            triangles = np.stack([np.full(len(k), indices[0]), indices[k], indices[k + 1]], axis=1)
        if len(triangles) == 0:
            self.fail(field, "holds no triangles")
        return np.ascontiguousarray(triangles, dtype=np.uint32)

    # -- materials and textures

    def primitive_material(self, spec, field):
        if "material" not in spec:
            return self.default
        return self.material(self.json.index(spec, "material", field, "materials", len(self.list("materials"))))

    def material(self, index):
        if index in self.materials:
            return self.materials[index]
        field = f"materials[{index}]"
        spec = self.element("materials", index)
        read = self.json
        pbr_field = f"{field}.pbrMetallicRoughness"
        pbr = read.get(spec, "pbrMetallicRoughness", field, {}, dict)
        base_color = read.vector(pbr, "baseColorFactor", pbr_field, [1.0, 1.0, 1.0, 1.0], length=4, nonnegative=True)
        emissive = read.vector(spec, "emissiveFactor", field, [0.0, 0.0, 0.0], nonnegative=True)
        for value, where in ((base_color, f"{pbr_field}.baseColorFactor"), (emissive, f"{field}.emissiveFactor")):
            if np.any(value > 1.0):
                self.fail(where, "must be at most 1 per channel")
        extensions = read.get(spec, "extensions", field, {}, dict)
        strength_spec = read.get(extensions, "KHR_materials_emissive_strength", f"{field}.extensions", {}, dict)
        strength = read.number(strength_spec, "emissiveStrength", f"{field}.extensions.KHR_materials_emissive_strength",
                               1.0, minimum=0.0)
        alpha_mode = read.get(spec, "alphaMode", field, "OPAQUE", str)
        if alpha_mode not in ALPHA_MODES:
            self.fail(f"{field}.alphaMode", f'must be one of {", ".join(ALPHA_MODES)}, got "{alpha_mode}"')
        uses = {"base_color_texture": self.texture(pbr, "baseColorTexture", pbr_field, srgb=True),
                "metallic_roughness_texture": self.texture(pbr, "metallicRoughnessTexture", pbr_field, srgb=False),
                "emissive_texture": self.texture(spec, "emissiveTexture", field, srgb=True),
                "normal_texture": self.texture(spec, "normalTexture", field, srgb=False)}
        normal_texture = uses["normal_texture"].texture
        material = Material(
            name=read.get(spec, "name", field, field, str),
            albedo=base_color[:3],
            alpha=float(base_color[3]),
            roughness=read.number(pbr, "roughnessFactor", pbr_field, 1.0, minimum=0.0, maximum=1.0),
            metalness=read.number(pbr, "metallicFactor", pbr_field, 1.0, minimum=0.0, maximum=1.0),
            specular=0.04,
            emission=emissive * strength,
            alpha_mode=alpha_mode,
            alpha_cutoff=read.number(spec, "alphaCutoff", field, 0.5, minimum=0.0) if alpha_mode == "MASK" else 0.5,
            double_sided=read.get(spec, "doubleSided", field, False, bool),
            normal_scale=read.number(spec["normalTexture"], "scale", f"{field}.normalTexture", 1.0) if normal_texture else 1.0,
            uv_sets={name: use.uv_set for name, use in uses.items() if use.uv_set},
            uv_transforms={name: use.transform for name, use in uses.items() if use.transform != IDENTITY_UV},
            **{name: use.texture for name, use in uses.items()},
        )
        emission_field = (f"{field}.emissiveFactor x extensions.KHR_materials_emissive_strength.emissiveStrength"
                          if strength_spec else f"{field}.emissiveFactor")
        check_material(material, self.fail, {
            "albedo": f"{pbr_field}.baseColorFactor", "alpha": f"{pbr_field}.baseColorFactor",
            "roughness": f"{pbr_field}.roughnessFactor", "metalness": f"{pbr_field}.metallicFactor",
            "emission": emission_field, "alpha_cutoff": f"{field}.alphaCutoff",
            "normal_scale": f"{field}.normalTexture.scale"})
        self.materials[index] = material
        return material

    def texture(self, obj, key, field, srgb):
        """The TextureUse of the textureInfo obj[key]: its Texture (None where there is none),
        the texture coordinate set it reads and the transform of its coordinates."""
        if key not in obj:
            return TextureUse(None, 0, IDENTITY_UV)
        read = self.json
        where = f"{field}.{key}"
        info = read.get(obj, key, field, kind=dict)
        index = read.index(info, "index", where, "textures", len(self.list("textures")))
        uv_set = int(read.number(info, "texCoord", where, 0, whole=True, minimum=0, maximum=1))
        transform = IDENTITY_UV
        extensions = read.get(info, "extensions", where, {}, dict)
        if "KHR_texture_transform" in extensions:
            uv_set, transform = self.texture_transform(extensions, f"{where}.extensions", uv_set)
        texture_field = f"textures[{index}]"
        spec = self.element("textures", index)
        if "source" not in spec:
            self.fail(texture_field, "has no source image (images in extensions, such as KHR_texture_basisu, are not read)")
        source = read.index(spec, "source", texture_field, "images", len(self.list("images")))
        wrap = ["REPEAT", "REPEAT"]
        if "sampler" in spec:
            sampler_index = read.index(spec, "sampler", texture_field, "samplers", len(self.list("samplers")))
            sampler = self.element("samplers", sampler_index)
            for k, axis in enumerate(("wrapS", "wrapT")):
                mode = read.get(sampler, axis, f"samplers[{sampler_index}]", 10497, int)
                if mode not in GLTF_WRAP_MODES:
                    self.fail(f"samplers[{sampler_index}].{axis}", f"must be one of {', '.join(map(str, GLTF_WRAP_MODES))}")
                wrap[k] = GLTF_WRAP_MODES[mode]
        image_field = f"images[{source}]"
        image = self.element("images", source)
        described = image.get("uri") or image.get("name")
        label = f'{image_field} "{_short(described)}"' if isinstance(described, str) else image_field
        try:
            pixels_key, _ = self.textures.decoded(self.image_bytes(image, image_field))
        except ValueError as exc:
            self.fail(where, f"{label}: {exc}")
        return TextureUse(self.textures.texture(pixels_key, f"{self.json.path}: {label}", srgb, *wrap), uv_set, transform)

    def texture_transform(self, extensions, field, uv_set):
        """(texture coordinate set, 2x3 matrix) of KHR_texture_transform: T(offset) R(rotation)
        S(scale) applied to (u, v, 1), as the extension defines R = [[cos, sin], [-sin, cos]]."""
        read, where = self.json, f"{field}.KHR_texture_transform"
        spec = read.get(extensions, "KHR_texture_transform", field, kind=dict)
        offset = read.vector(spec, "offset", where, [0.0, 0.0], length=2)
        rotation = read.number(spec, "rotation", where, 0.0)
        scale = read.vector(spec, "scale", where, [1.0, 1.0], length=2)
        uv_set = int(read.number(spec, "texCoord", where, uv_set, whole=True, minimum=0, maximum=1))
        c, s = math.cos(rotation), math.sin(rotation)
        return uv_set, ((c * scale[0], s * scale[1], float(offset[0])), (-s * scale[0], c * scale[1], float(offset[1])))

    def image_bytes(self, image, field):
        if "bufferView" in image:
            data, offset, length, _ = self.view_bytes(self.json.index(image, "bufferView", field, "bufferViews",
                                                                      len(self.list("bufferViews"))))
            return data[offset:offset + length]
        if "uri" in image:
            return self._uri_bytes(self.json.get(image, "uri", field, kind=str))
        self.fail(field, "has neither uri nor bufferView")


def _short(text, limit=60):
    """A URI for messages: data URIs can be megabytes long."""
    return text if len(text) <= limit else text[:limit] + "..."


TextureUse = namedtuple("TextureUse", "texture uv_set transform")
