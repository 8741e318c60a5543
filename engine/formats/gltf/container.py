"""The container of a glTF file: its JSON document (from a .gltf, or the chunks of a .glb), its
buffers (embedded, data URIs, external files read through the scene's InputFiles), buffer views
and accessors (strided and sparse ones too) decoded with numpy, and the bytes of its images."""
import base64
import json
import math
import struct
import urllib.parse
from pathlib import Path

import numpy as np

from ...core.errors import warn
from ...core.limits import MAX_DECODED_BYTES, MAX_FILE_BYTES, check_vertices
from ..input_files import os_problem
from ..json_reader import JsonReader

COMPONENT_TYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
FLOAT = (5126,)
INDEX_TYPES = (5121, 5123, 5125)
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
GLB_JSON, GLB_BIN = 0x4E4F534A, 0x004E4942


class GltfContainer:
    """A glTF file's document and data: where the readers of its parts (engine/formats/gltf/)
    take their arrays and report their errors."""

    def __init__(self, path, data, name, inputs):
        self.path = Path(path)
        self.json = JsonReader(name)
        self.inputs = inputs
        self.glb_bin = None
        self.doc = self._document(data)
        self.buffers = {}
        self.decoded = set()  # the accessors decoded so far, and their bytes
        self.decoded_bytes = 0

    def fail(self, field, message):
        self.json.fail(field, message)

    def list(self, key):
        return self.json.get(self.doc, key, "", [], list)

    def element(self, key, index):
        value = self.list(key)[index]
        if not isinstance(value, dict):
            self.fail(f"{key}[{index}]", "must be an object")
        return value


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
            end = offset + 8 + size
            offset = end + (-size % 4)
            if size % 4 and not _chunk_at(data, offset, length) and _chunk_at(data, end, length):
                warn(f"GLB chunk {len(chunks) - 1} is not padded to 4 bytes: the next chunk read where it was written",
                     source=self.json.path)
                offset = end
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
                    self.fail(f"{field}.uri", f'"{short_uri(uri)}": {exc}')
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
        if index not in self.decoded:
            if self.decoded_bytes + count * element > MAX_DECODED_BYTES:
                self.fail(f"{where}.count", f"the file's accessors would decode to more than {MAX_DECODED_BYTES // 2 ** 30} GiB "
                                            "together")
            self.decoded.add(index)
            self.decoded_bytes += count * element
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

    def image_bytes(self, image, field):
        if "bufferView" in image:
            data, offset, length, _ = self.view_bytes(self.json.index(image, "bufferView", field, "bufferViews",
                                                                      len(self.list("bufferViews"))))
            return data[offset:offset + length]
        if "uri" in image:
            return self._uri_bytes(self.json.get(image, "uri", field, kind=str))
        self.fail(field, "has neither uri nor bufferView")


def _chunk_at(data, offset, length):
    """Whether a GLB chunk header of a known kind, fitting the file, starts at `offset`."""
    if offset + 8 > length:
        return False
    size, kind = struct.unpack_from("<II", data, offset)
    return kind in (GLB_JSON, GLB_BIN) and offset + 8 + size <= length


def short_uri(text, limit=60):
    """A URI for messages: data URIs can be megabytes long."""
    return text if len(text) <= limit else text[:limit] + "..."

