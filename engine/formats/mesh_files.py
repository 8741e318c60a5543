"""Mesh files -> scene-graph nodes with meshes, materials and textures (plain Python/numpy, no GL).

- glTF 2.0 (.gltf with its buffers and images, or .glb): read by engine/formats/gltf/ (its
  node hierarchy, meshes, materials, textures, cameras, KHR_lights_punctual lights and
  animations; its docstring says how).
- OBJ + MTL: one node per material (usemtl) group, named after its material. MTL, per
  material: Kd (x map_Kd) -> albedo (Kd defaults to 1 with map_Kd, else 0.8); Ke (x map_Ke) ->
  emission (Ke defaults to 1 with map_Ke, else 0); Ns -> roughness r = (2 / (Ns + 2))^(1/4),
  the inverse of the renderer's Blinn-Phong exponent 2/r^4 - 2 (no Ns: r = 1); Ks not black
  -> specular 0.04 (a dielectric, as glTF's), else 0 (Lambertian); d (or Tr = 1 - d, with a
  warning where it makes the material fully transparent) and map_d -> alpha, with alpha_mode
  BLEND (map_d's alpha channel, or its grey level where it has none, becomes the alpha of the
  base-colour texture). Metalness
  0, one-sided. Texture options other than -clamp are refused; other statements are ignored.
  Faces of four corners or more are cut into triangles in their plane (concave ones too).
  Normals from the file (vn), else computed, smooth but at creases (mesh_building.py). OBJ's
  texture v grows upwards; it is flipped to glTF's convention (see engine.scene.model.Texture).
- PLY, STL and OFF (read by trimesh): one mesh, its normals computed as an OBJ's without vn. trimesh's other formats
  are not read: its archives (zip, tar, bz2) decompress without a bound, and the rest hold no
  triangles.

Images are decoded once per file: materials that use the same image (by content) the same way
share one Texture object. Parts without a material in the file get a grey Lambertian default
(albedo 0.8, like a scene material with no fields). Every file is read through the scene's
InputFiles (engine/formats/input_files.py: regular files, size and pixel limits), and what a file
holds is held to engine/core/limits.py: vertex data finite and within +-1e6, materials within
their ranges, nodes nested at most MAX_DEPTH levels (the scene checks the world transforms
of the nodes it places). Bad input raises SceneError naming the file and the element, e.g.
`sponza.glb: materials[3].pbrMetallicRoughness.baseColorTexture: images[5] "bricks.png": file
not found`.
"""
import io
import re
from collections import namedtuple
from pathlib import Path

import numpy as np

from ..core.errors import SceneError, warn
from ..core.limits import check_material
from ..scene.model import Material, Node
from .gltf import GltfFile
from .input_files import InputFiles, os_problem
from .mesh_building import FileTextures, default_material, polygon_triangles, quad_triangles, surface_mesh, warn_dropped

TRIMESH_FORMATS = (".ply", ".stl", ".off")
MESH_SUFFIXES = (".gltf", ".glb", ".obj", *TRIMESH_FORMATS)


def load_mesh_file(path, name, material=None, inputs=None):
    """The top-level nodes of the mesh file at `path`; `name` names it in errors (as the scene
    file writes it). With `material`, every part uses it and the file's materials and textures
    are not read; otherwise each part has its material from the file. `inputs` (InputFiles)
    reads the file and what it names within the scene's budget (a new one by default)."""
    inputs = inputs or InputFiles()
    try:
        data = inputs.read(path)
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        raise SceneError(f"cannot read ({os_problem(exc)})", source=name) from None
    suffix = Path(path).suffix.lower()
    if suffix in (".gltf", ".glb"):
        return GltfFile(path, data, name, material, inputs).nodes()
    if suffix == ".obj":
        return _load_obj(path, data, name, material, inputs)
    if suffix in TRIMESH_FORMATS:
        return [_load_with_trimesh(path, data, name, material)]
    raise SceneError(f"not a mesh format vct reads (by its suffix: .gltf, .glb, .obj, {', '.join(TRIMESH_FORMATS)})",
                     source=name)



# ---- OBJ + MTL -----------------------------------------------------------------------------

def _statements(text, keyword):
    """The arguments of every line `keyword ...`, in file order (a literal prefix, so the
    search is fast on files of millions of lines)."""
    return [m.strip() for m in re.findall(rf"\n{keyword}[ \t]+([^\r\n]*)", "\n" + text)]


_POLYGON = re.compile(r"^f[ \t]+\S+[ \t]+\S+[ \t]+\S+[ \t]+\S", re.MULTILINE)  # a face of four corners or more


def _triangulated(text, name):
    """The OBJ text with each face of more than three corners written as triangles
    (quad_triangles, polygon_triangles: right for concave faces too); the text itself where
    every face is a triangle."""
    if not _POLYGON.search(text):
        return text
    lines = text.split("\n")
    positions, polygons = [], []  # polygons: (line index, corner words, position indices)
    for number, line in enumerate(lines):
        words = line.split("#", 1)[0].split()
        if not words:
            continue
        if words[0] == "v":
            positions.append(words[1:4])
        elif words[0] == "f" and len(words) > 4:
            try:
                refs = [int(word.split("/", 1)[0]) for word in words[1:]]
            except ValueError:
                raise SceneError("a face's corners must be whole vertex numbers", source=name, field=f"line {number + 1}") from None
            corners = [ref - 1 if ref > 0 else len(positions) + ref for ref in refs]
            if not all(0 <= corner < len(positions) for corner in corners):
                raise SceneError(f"a face names a vertex beyond the {len(positions)} before it", source=name,
                                 field=f"line {number + 1}")
            polygons.append((number, words[1:], corners))
    try:
        points = np.array(positions, np.float64)
    except ValueError:
        raise SceneError("a vertex (v) must have three numbers", source=name) from None
    quads = [polygon for polygon in polygons if len(polygon[1]) == 4]
    if quads:
        split = quad_triangles(points[np.array([corners for _, _, corners in quads])])
        for (number, words, _), triangles in zip(quads, split):
            lines[number] = "\n".join("f " + " ".join(words[i] for i in triangle) for triangle in triangles)
    for number, words, corners in polygons:
        if len(words) > 4:
            triangles = polygon_triangles(points[corners])
            lines[number] = "\n".join("f " + " ".join(words[i] for i in triangle) for triangle in triangles)
    return "\n".join(lines)


def _load_obj(path, data, name, material, inputs):
    from trimesh.exchange.obj import load_obj

    path = Path(path)
    text = _triangulated(data.decode("utf-8", errors="replace"), name)
    data = text.encode()
    if material is not None:  # one material for the file: its groups do not matter (trimesh names groups in quadratic time)
        data = "\n".join(line for line in text.splitlines()
                         if line.split(maxsplit=1)[:1] not in (["usemtl"], ["mtllib"])).encode()
        text = data.decode()
    groups = list(dict.fromkeys(_statements(text, "usemtl")))
    # trimesh groups faces by usemtl but names a group after its material only where it loaded
    # that material, so it reads a library of just the names; the real MTL is read here, as
    # trimesh's MTL reader drops a texture it cannot open without a word and skips map_Ke/map_d.
    names = "\n".join(f"newmtl {group}" for group in groups).encode()
    try:
        loaded = load_obj(io.BytesIO(b"mtllib vct-material-names.mtl\n" + data),
                          resolver={"vct-material-names.mtl": names}, group_material=True)
    except Exception as exc:  # trimesh raises many kinds on malformed files
        raise _unloadable(name, "OBJ", exc) from None
    library = None if material is not None else _MtlLibrary(path, name, _statements(text, "mtllib"), inputs)
    parts, dropped = [], 0
    for kwargs in loaded.get("geometry", {}).values():
        visual = kwargs.get("visual")
        group = getattr(getattr(visual, "material", None), "name", None)
        group = group if group in groups else None
        part_material = material or library.material(group)
        uv = getattr(visual, "uv", None)
        positions = np.asarray(kwargs["vertices"], np.float64)
        triangles = np.asarray(kwargs["faces"], np.int64)
        if len(triangles) == 0:
            continue
        texcoords = None
        if uv is not None and len(uv) == len(positions):
            texcoords = np.column_stack([uv[:, 0], 1.0 - uv[:, 1]])
        if part_material.textures() and texcoords is None:
            raise SceneError(f'material "{part_material.name}" has textures but its faces have no texture coordinates (vt)',
                             source=name, field=f'usemtl "{group}"')
        mesh, dropped_here = surface_mesh(positions, triangles, kwargs.get("vertex_normals"), texcoords)
        dropped += dropped_here
        if mesh is not None:
            parts.append((groups.index(group) if group is not None else -1,
                          Node(name=group or path.stem, mesh=mesh, material=part_material)))
    warn_dropped(name, dropped)
    return [node for _, node in sorted(parts, key=lambda part: part[0])]


class _MtlLibrary:
    """The materials of an OBJ's mtllib files, each made on first use (see the module docstring)."""

    def __init__(self, obj_path, obj_name, libraries, inputs):
        self.obj_name = obj_name
        self.inputs = inputs
        self.statements = {}  # material name -> (MTL path, MTL name, [(line number, keyword, arguments)])
        self.made = {None: default_material()}
        self.textures = FileTextures(inputs)
        for library in libraries:
            for file in library.split():
                self._read(obj_path.parent / file, str(Path(obj_name).parent / file), file)

    def _read(self, path, name, file):
        try:
            text = self.inputs.read(path).decode("utf-8", errors="replace")
        except (OSError, ValueError) as exc:
            raise SceneError(f"cannot read material library: {os_problem(exc)}", source=self.obj_name,
                             field=f'mtllib "{file}"') from None
        current = None
        for number, line in enumerate(text.splitlines(), 1):
            words = line.split("#", 1)[0].split()
            if words and words[0].lower() == "newmtl":
                current = " ".join(words[1:])
                self.statements[current] = (path, name, [])
            elif words and current is not None:
                self.statements[current][2].append((number, words[0], words[1:]))

    def material(self, group):
        if group not in self.made:
            if group not in self.statements:
                raise SceneError("no material of that name in the mtllib files", source=self.obj_name,
                                 field=f'usemtl "{group}"')
            self.made[group] = self._material(group, *self.statements[group])
        return self.made[group]

    def _material(self, group, path, name, statements):
        values, maps, lines = {}, {}, {}
        for number, keyword, args in statements:
            where = f"line {number} ({keyword})"
            key = keyword.lower()
            lines[key] = where
            if key in ("kd", "ke", "ks"):
                values[key] = _mtl_numbers(args, name, where, (1, 3), maximum=1.0 if key == "kd" else None) * np.ones(3)
            elif key in ("ns", "d", "tr"):
                values[key] = float(_mtl_numbers(args, name, where, (1,), maximum=None if key == "ns" else 1.0)[0])
            elif key in ("map_kd", "map_ke", "map_d"):
                maps[key] = self._map(args, path, name, where)
        alpha = values.get("d", 1.0 - values.get("tr", 0.0))  # Tr is transparency, 1 - d
        if alpha == 0.0 and "map_d" not in maps:
            line = lines.get("d", lines.get("tr"))
            warn(f"fully transparent (alpha 0), so never seen{' (Tr is 1 - d: Tr 1 is transparent)' if 'd' not in values else ''}",
                 source=name, field=f'newmtl "{group}": {line}')
        ns = values.get("ns")
        material = Material(
            name=group,
            albedo=values.get("kd", np.ones(3) if "map_kd" in maps else np.full(3, 0.8)),
            roughness=1.0 if ns is None else (2.0 / (ns + 2.0)) ** 0.25,
            specular=0.04 if np.any(values.get("ks", 0.0) > 0) else 0.0,
            emission=values.get("ke", np.ones(3) if "map_ke" in maps else np.zeros(3)),
            alpha=alpha,
            alpha_mode="BLEND" if alpha < 1.0 or "map_d" in maps else "OPAQUE",
            base_color_texture=self._base_color(maps.get("map_kd"), maps.get("map_d")),
            emissive_texture=self._texture(maps.get("map_ke"), srgb=True),
        )
        fields = {"albedo": lines.get("kd"), "emission": lines.get("ke"), "alpha": lines.get("d", lines.get("tr")),
                  "roughness": lines.get("ns")}
        check_material(material, lambda field, message: _mtl_failure(name, field, message),
                       {key: f'newmtl "{group}": {line}' for key, line in fields.items() if line})
        return material

    def _map(self, args, mtl_path, mtl_name, where):
        """The image a map statement names (options: -clamp on|off)."""
        wrap = "REPEAT"
        while args and args[0].startswith("-"):
            if args[0] != "-clamp" or len(args) < 2 or args[1] not in ("on", "off"):
                raise SceneError(f"texture option {args[0]} is not supported (only -clamp on|off)", source=mtl_name, field=where)
            wrap = "CLAMP_TO_EDGE" if args[1] == "on" else "REPEAT"
            args = args[2:]
        file = " ".join(args).replace("\\", "/")
        if not file:
            raise SceneError("names no image file", source=mtl_name, field=where)
        try:
            data = self.inputs.read(mtl_path.parent / file)
        except (OSError, ValueError) as exc:
            raise SceneError(f'"{file}": {os_problem(exc)}', source=mtl_name, field=where) from None
        try:
            key, pixels = self.textures.decoded(data)
        except ValueError as exc:
            raise SceneError(f'"{file}": {exc}', source=mtl_name, field=where) from None
        return _MapImage(str(Path(mtl_name).parent / file), key, pixels, wrap)

    def _texture(self, image, srgb):
        return None if image is None else self.textures.texture(image.key, image.name, srgb, image.wrap, image.wrap)

    def _base_color(self, color, alpha):
        """map_Kd, with map_d's alpha where there is a map_d (the image itself where both name
        the same image with an alpha channel)."""
        if alpha is None or (color is not None and color.key == alpha.key and color.pixels.shape[2] in (2, 4)):
            return self._texture(color, srgb=True)
        key = (color.key if color else None, alpha.key)
        self.textures.pixels(key, lambda: _with_alpha(color.pixels if color else None, alpha.pixels))
        name = f"{color.name if color else 'white'} with the alpha of {alpha.name}"
        wrap = (color or alpha).wrap
        return self.textures.texture(key, name, True, wrap, wrap)



_MapImage = namedtuple("_MapImage", "name key pixels wrap")


def _with_alpha(color, alpha):
    """RGBA pixels: `color`'s RGB (white where None) with the alpha channel of `alpha`, or its
    first channel where it has no alpha, resized to `color`'s size."""
    from PIL import Image

    a = alpha[..., -1] if alpha.shape[2] in (2, 4) else alpha[..., 0]
    if color is None:
        rgb = np.full(a.shape + (3,), 255, np.uint8)
    else:
        rgb = color[..., :3] if color.shape[2] >= 3 else np.repeat(color[..., :1], 3, axis=2)
    if a.shape != rgb.shape[:2]:
        a = np.asarray(Image.fromarray(a).resize((rgb.shape[1], rgb.shape[0]), Image.BILINEAR))
    return np.ascontiguousarray(np.dstack([rgb, a]))


def _mtl_numbers(args, mtl_name, where, counts, maximum=None):
    try:
        values = np.array([float(a) for a in args])
    except ValueError:
        values = None
    if values is None or len(values) not in counts or not np.all(np.isfinite(values)):
        raise SceneError(f"must be {' or '.join(map(str, counts))} finite numbers", source=mtl_name, field=where)
    if np.any(values < 0) or (maximum is not None and np.any(values > maximum)):
        raise SceneError(f"must be {'in 0..' + str(maximum) if maximum is not None else 'at least 0'}", source=mtl_name, field=where)
    return values


def _mtl_failure(mtl_name, field, message):
    raise SceneError(message, source=mtl_name, field=field)


# ---- other formats -------------------------------------------------------------------------

def _load_with_trimesh(path, data, name, material):
    """PLY, STL, OFF: one mesh, merged vertices, smooth normals."""
    import trimesh

    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=Path(path).suffix.lstrip(".").lower(), force="mesh", process=True)
    except Exception as exc:  # trimesh raises many kinds on unreadable files
        raise _unloadable(name, Path(path).suffix.lstrip(".").upper(), exc) from None
    mesh = None
    if isinstance(loaded, trimesh.Trimesh) and len(loaded.faces):
        mesh, dropped = surface_mesh(np.asarray(loaded.vertices, np.float64), np.asarray(loaded.faces, np.int64))
        warn_dropped(name, dropped)
    if mesh is None:
        raise SceneError("holds no triangles", source=name)
    return Node(name=Path(path).stem, mesh=mesh, material=material or default_material())


def _unloadable(name, kind, exc):
    """The error of a mesh file trimesh could not read."""
    if isinstance(exc, ImportError):  # trimesh guesses the encoding of text that is not UTF-8 with an optional module
        return SceneError(f"cannot load mesh: neither a binary {kind} file nor UTF-8 text", source=name)
    return SceneError(f"cannot load mesh: {' '.join(str(exc).split()) or type(exc).__name__}", source=name)
