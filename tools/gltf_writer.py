"""A small glTF 2.0 (GLB) writer for the tools that make the project's test models
(make_textured_box.py, make_gltf_room.py, make_leaf_screen.py): arrays into one binary buffer, PNG images embedded."""
import io
import json
import struct

import numpy as np
from PIL import Image


class Gltf:
    def __init__(self, generator):
        self.doc = {"asset": {"version": "2.0", "generator": generator}, "scene": 0,
                    "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [], "textures": [],
                    "images": [], "samplers": [], "accessors": [], "bufferViews": [], "buffers": [{"byteLength": 0}]}
        self.blob = bytearray()

    def add(self, key, spec):
        self.doc.setdefault(key, []).append(spec)
        return len(self.doc[key]) - 1

    def view(self, data, target=None):
        self.blob += b"\0" * (-len(self.blob) % 4)
        spec = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            spec["target"] = target
        self.blob += data
        return self.add("bufferViews", spec)

    def accessor(self, array, kind, component=5126, target=34962):
        array = np.asarray(array)
        data = array.astype("<f4" if component == 5126 else "<u2").tobytes()
        spec = {"bufferView": self.view(data, target), "componentType": component, "count": len(array), "type": kind}
        if kind in ("VEC3", "SCALAR") and component == 5126:  # required of positions and animation times
            spec["min"], spec["max"] = np.atleast_1d(array.min(axis=0)).tolist(), np.atleast_1d(array.max(axis=0)).tolist()
        return self.add("accessors", spec)

    def animation(self, name, channels):
        """An animation of channels (node, path, times, values, interpolation): `values` one
        row per time, three (in-tangent, value, out-tangent) with CUBICSPLINE."""
        samplers, targets = [], []
        for node, path, times, values, interpolation in channels:
            kind = "VEC4" if path == "rotation" else "VEC3"
            samplers.append({"input": self.accessor(np.asarray(times, float), "SCALAR", target=None),
                             "output": self.accessor(np.asarray(values, float), kind, target=None),
                             "interpolation": interpolation})
            targets.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})
        return self.add("animations", {"name": name, "samplers": samplers, "channels": targets})

    def texture(self, pixels, name, sampler=0):
        out = io.BytesIO()
        Image.fromarray(pixels).save(out, format="PNG")
        image = self.add("images", {"name": name, "bufferView": self.view(out.getvalue()), "mimeType": "image/png"})
        return self.add("textures", {"source": image, "sampler": sampler})

    def mesh(self, name, geometry, material, colors=None):
        """A mesh of one primitive: geometry = (positions, normals, texcoords, indices); `colors`
        (V, 3): its COLOR_0."""
        positions, normals, texcoords, indices = geometry
        attributes = {"POSITION": self.accessor(positions, "VEC3"), "NORMAL": self.accessor(normals, "VEC3"),
                      "TEXCOORD_0": self.accessor(texcoords, "VEC2")}
        if colors is not None:
            attributes["COLOR_0"] = self.accessor(colors, "VEC3")
        primitive = {"attributes": attributes, "indices": self.accessor(indices, "SCALAR", 5123, 34963), "material": material}
        return self.add("meshes", {"name": name, "primitives": [primitive]})

    def glb(self):
        self.doc["buffers"][0]["byteLength"] = len(self.blob)
        text = json.dumps(self.doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        blob = bytes(self.blob) + b"\0" * (-len(self.blob) % 4)
        chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
        return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def unit_quad():
    """(positions, normals, texcoords, indices) of a unit square in the xy plane facing +z, its
    image's top at +y and left at -x (glTF texture coordinates: (0, 0) the image's top-left)."""
    positions = np.array([[-0.5, 0.5, 0], [-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0]], float)
    texcoords = np.array([[0, 0], [0, 1], [1, 1], [1, 0]], float)
    return positions, np.tile([0.0, 0.0, 1.0], (4, 1)), texcoords, np.array([0, 1, 2, 0, 2, 3])


def write_models(models):
    """Write each (path, GLB bytes) of `models`, making the folders, and say so."""
    for path, data in models:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
        print(f"wrote {path} ({path.stat().st_size} bytes)")

