"""A glTF file's meshes: each primitive's triangles and vertex attributes."""
import numpy as np

from ...core.errors import warn
from ...core.limits import MAX_FILE_TRIANGLES
from ...scene.model import TEXTURE_FIELDS, Mesh, MorphTarget
from ..mesh_building import flat_normals, generate_tangents, with_area
from .container import FLOAT, INDEX_TYPES

NORMALIZED_UV_TYPES = (5121, 5123)
MODE_NAMES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP"}


class MeshReader:
    """Part of GltfFile: meshes, each primitive made once."""

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
            weights = self.json.get(self.element("meshes", index), "weights", field, None, list)
            for mesh, _ in self.meshes[index]:
                if mesh.targets and weights is not None:
                    mesh.target_weights = self.json.vector_value(weights, f"{field}.weights", len(mesh.targets))
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
        if "POSITION" not in attributes:  # glTF: a primitive without positions is not drawn
            self.positionless.append(field)
            return None
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
        joints, weights = self.influences(attributes, where, len(positions))
        targets = self.targets(spec, field, len(positions))
        if "indices" in spec:
            indices = self.accessor(spec, "indices", field, ("SCALAR",), INDEX_TYPES, as_float=False)[:, 0].astype(np.uint32)
            if indices.max() >= len(positions):
                self.fail(f"{field}.indices", f"refers to vertex {int(indices.max())}, the primitive has {len(positions)}")
        else:
            indices = np.arange(len(positions), dtype=np.uint32)
        triangles = self.triangles(indices, mode, field)
        triangles = with_area(positions, triangles)
        material = self.override or self.primitive_material(spec, field)
        normals, tangents = found.get("NORMAL"), found.get("TANGENT")
        texcoords, texcoords1 = found.get("TEXCOORD_0"), found.get("TEXCOORD_1")
        colors = found["COLOR_0"][:, :3] if "COLOR_0" in found else None
        if colors is not None and (colors.max() > 1.0 or colors.min() < 0.0):  # they multiply the albedo: held to its 0..1
            warn(f"COLOR_0 values within {colors.min():.3g}..{colors.max():.3g} clamped to 0..1, the albedo's range",
                 source=self.json.path, field=f"accessors[{attributes['COLOR_0']}]")
            colors = np.clip(colors, 0.0, 1.0)
        if normals is not None:
            normals = self.unit_normals(normals, f"{where}.NORMAL", attributes["NORMAL"])
        for texture_field in (f for f in TEXTURE_FIELDS if getattr(material, f) is not None):
            uv_set = material.uv_sets.get(texture_field, 0)
            if (texcoords, texcoords1)[uv_set] is None:
                self.fail(field, f'material "{material.name}" has textures on TEXCOORD_{uv_set} but the primitive has no '
                                 f"TEXCOORD_{uv_set}")
        if normals is None:  # flat: every corner its own vertex, the targets' normals left out
            target_arrays = [array for target in targets for array in (target.positions, target.tangents)]
            positions, normals, triangles, texcoords, tangents, colors, texcoords1, joints, weights, *target_arrays = flat_normals(
                positions, triangles, texcoords, tangents, colors, texcoords1, joints, weights, *target_arrays)
            targets = tuple(MorphTarget(target_arrays[2 * k], None, target_arrays[2 * k + 1]) for k in range(len(targets)))
        if material.normal_texture is not None and tangents is None:
            normal_uv = (texcoords, texcoords1)[material.uv_sets.get("normal_texture", 0)]
            tangents = generate_tangents(positions, normals, normal_uv, triangles)
        if len(triangles) == 0:
            return None
        return Mesh(positions, normals, triangles, texcoords, tangents, colors, texcoords1, joints, weights, targets), material

    def influences(self, attributes, where, count):
        """(joints, weights), (V, 4 k) each, of JOINTS_n and WEIGHTS_n (n = 0 .. k - 1, sets in
        pairs), the weights of each vertex scaled to sum to 1 (glTF requires it, exporters round);
        (None, None) where there are none."""
        sets = 0
        while f"JOINTS_{sets}" in attributes and f"WEIGHTS_{sets}" in attributes:
            sets += 1
        if not sets:
            return None, None
        joints, weights = [], []
        for n in range(sets):
            joints.append(self.accessor(attributes, f"JOINTS_{n}", where, ("VEC4",), (5121, 5123), as_float=False))
            weights.append(self.accessor(attributes, f"WEIGHTS_{n}", where, ("VEC4",), FLOAT + NORMALIZED_UV_TYPES))
            for key, array in ((f"JOINTS_{n}", joints[-1]), (f"WEIGHTS_{n}", weights[-1])):
                if len(array) != count:
                    self.fail(f"{where}.{key}", f"has {len(array)} elements, POSITION {count}")
        joints, weights = np.hstack(joints).astype(np.uint32), np.hstack(weights).astype(np.float32)
        if np.any(weights < 0):
            self.fail(f"{where}.WEIGHTS_0", "weights must not be negative")
        sums = weights.sum(axis=1, keepdims=True)
        weights = np.divide(weights, sums, out=np.zeros_like(weights), where=sums > 0)
        weights[sums[:, 0] <= 0, 0] = 1.0  # a vertex no joint moves follows its first joint
        return joints, weights

    def targets(self, spec, field, count):
        """The MorphTargets of a primitive (POSITION, NORMAL, TANGENT displacements)."""
        targets = []
        for t, target in enumerate(self.json.get(spec, "targets", field, [], list)):
            where = f"{field}.targets[{t}]"
            if not isinstance(target, dict):
                self.fail(where, "must be an object")
            arrays = []
            for key in ("POSITION", "NORMAL", "TANGENT"):
                array = self.accessor(target, key, where, ("VEC3",), FLOAT) if key in target else None
                if array is not None and len(array) != count:
                    self.fail(f"{where}.{key}", f"has {len(array)} elements, POSITION {count}")
                arrays.append(array)
            targets.append(MorphTarget(*arrays))
        return tuple(targets)

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
        """The (T, 3) triangles of a primitive's indices, counted against the file's
        MAX_FILE_TRIANGLES before strips and fans are expanded."""
        count = len(indices) // 3 if mode == 4 else max(len(indices) - 2, 0)
        self.triangle_count += count
        if self.triangle_count > MAX_FILE_TRIANGLES:
            self.fail(field, f"the file's primitives would hold more than {MAX_FILE_TRIANGLES} triangles")
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

