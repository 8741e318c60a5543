"""Scenes built in code (plain Python/numpy, no GL): meshes from arrays, the limits a scene
built by hand is held to, and trimesh meshes and scenes as engine Scenes.

- `triangle_mesh(positions, indices, ...)`: a Mesh of triangles, its normals computed where
  none are given.
- `check_scene(scene)`: the limits of engine/core/limits.py that loaded scenes are held to, for a
  scene put together from engine.scene.model's dataclasses.
- `from_trimesh(scene_or_mesh)`: a trimesh.Trimesh or trimesh.Scene as a Scene. Its graph's
  nodes become Nodes (names, parents, translation, rotation and scale from each node's
  matrix; shear is refused); each geometry becomes one Mesh and one Material, shared by the
  nodes that place it. Colours are read as trimesh's glTF export writes them: 8-bit values
  / 255, taken as linear (glTF's baseColorFactor and COLOR_0).

  - Normals: the ones trimesh holds for the mesh (read from its file or set, or computed by
    an earlier read of `mesh.vertex_normals`: the test trimesh's glTF export makes), else
    computed from the faces as for every mesh file without normals: smooth across edges where
    faces meet at less than CREASE_DEG (trimesh's own smooth-shading angle), the vertices
    split at sharper edges.
  - PBRMaterial, field by field as the glTF loader reads the same material: albedo, alpha =
    baseColorFactor (default 1); metalness, roughness = metallicFactor, roughnessFactor
    (default 1, glTF's); emission = emissiveFactor, in W/(m^2 sr); base_color_texture
    (sRGB), metallic_roughness_texture, normal_texture (linear), emissive_texture (sRGB)
    from the PIL images, repeating; specular 0.04; alphaMode, alphaCutoff (for MASK; 0.5
    otherwise), doubleSided. occlusionTexture is not read.
  - SimpleMaterial, as an MTL material is read: albedo, alpha = diffuse (alpha below 1:
    BLEND), base_color_texture = image, roughness (2 / (glossiness + 2))^(1/4), specular
    0.04 where its specular colour is not black, else 0.
  - Vertex colours (ColorVisuals, or a TextureVisuals' "color" attribute) become Mesh.colors,
    multiplying the base colour; without a material the colours are the albedo (a material
    of albedo 1). Face colours give every face its own vertices, in its colour. A geometry
    with neither material nor colours gets the loaders' grey default (albedo 0.8).
  - Texture coordinates (TextureVisuals.uv, v upwards) are flipped to glTF's convention
    (engine.scene.model.Texture); a material with textures needs them. Tangents are generated where
    a material has a normal texture.
  - The camera: the scene's own where one was set (`trimesh.Scene.has_camera`: its vertical
    field of view, resolution and transform, looking along its node's -z), else one framing
    the scene's bounds. trimesh's lights (its viewer's, without units) are not read: the scene
    has no light until one is added (a Node with a Light).

  The result is held to the limits of loaded scenes (check_scene, and the image limits of
  engine/formats/input_files.py for the textures). Bad input raises VctError: a wrong argument names
  it, a fault in the scene is a SceneError naming the trimesh element, e.g. `trimesh scene
  "demo": node "arm".matrix: is not a translation, rotation and scale (it shears or
  projects), which are all a node holds`.
"""
import io

import numpy as np

from ..core.errors import SceneError, VctError
from ..core.limits import MAX_DEPTH, MIN_FOV_DEG, check_material, check_placement, check_vertices
from ..core.transforms import decompose
from ..scene.model import TEXTURE_FIELDS, Material, Mesh, Node, NodeCamera, Scene
from .input_files import InputFiles
from .mesh_building import FileTextures, crease_normals, default_material, generate_tangents, with_area
from .scene_file import DEFAULT_WIDTH, FALLBACK_ASPECT, framing_camera

MAX_FOV_DEG = 179.0
# The PIL image of each texture field of a trimesh PBRMaterial, and whether it holds sRGB colour.
PBR_TEXTURES = {"base_color_texture": ("baseColorTexture", True),
                "metallic_roughness_texture": ("metallicRoughnessTexture", False),
                "emissive_texture": ("emissiveTexture", True),
                "normal_texture": ("normalTexture", False)}
# What trimesh calls the fields of engine.Material it sets, for messages.
PBR_FIELDS = {"albedo": "baseColorFactor", "alpha": "baseColorFactor", "roughness": "roughnessFactor",
              "metalness": "metallicFactor", "emission": "emissiveFactor", "alpha_cutoff": "alphaCutoff"}
SIMPLE_FIELDS = {"albedo": "diffuse", "alpha": "diffuse", "roughness": "glossiness"}
PNG_MODES = ("1", "L", "LA", "I;16", "P", "RGB", "RGBA")  # the image modes PIL writes as PNG


# ---- meshes from arrays ------------------------------------------------------------------------

def triangle_mesh(positions, indices, normals=None, texcoords=None, colors=None):
    """A Mesh of triangles: `positions` (V, 3) in metres; `indices` (T, 3) whole numbers (or a
    flat sequence of 3T) into them, each triangle counter-clockwise seen from its front;
    optionally `normals` (V, 3), scaled to unit length (None: computed, smooth and
    angle-weighted across edges where faces meet at less than CREASE_DEG, sharp at sharper
    ones: engine/formats/mesh_building.py), `texcoords`
    (V, 2) in glTF's convention ((0, 0) is the image's top-left corner, v grows downwards:
    engine.Texture) and `colors` (V, 3) linear RGB in 0..1 multiplying the material's base
    colour. Every value is finite and within the limits of loaded meshes; triangles of zero
    area are dropped (they draw nothing). Bad input raises VctError naming the argument."""
    def fail(argument, message):
        raise VctError(message, field=argument)

    mesh = _mesh(positions, indices, normals, texcoords, colors, fail)
    if mesh is None:
        fail("indices", "no triangle has an area (every one has collinear corners)")
    return mesh


def _mesh(positions, indices, normals, texcoords, colors, fail):
    """triangle_mesh's Mesh, None where no triangle has an area; `fail(argument, message)`
    raises the caller's error for the argument at fault."""
    positions = _vertex_array(positions, "positions", 3, None, fail)
    triangles = _triangles(indices, len(positions), fail)
    normals = None if normals is None else _vertex_array(normals, "normals", 3, len(positions), fail)
    texcoords = None if texcoords is None else _vertex_array(texcoords, "texcoords", 2, len(positions), fail)
    if colors is not None:
        colors = _vertex_array(colors, "colors", (3, 4), len(positions), fail)[:, :3]  # alpha is not read (COLOR_0's)
        if np.any((colors < 0) | (colors > 1)):
            element = int(np.argmax(np.any((colors < 0) | (colors > 1), axis=1)))
            fail("colors", f"element {element} is {colors[element].tolist()}: each component must be within 0..1")
    triangles = with_area(positions, triangles)
    if len(triangles) == 0:
        return None
    used, triangles = np.unique(triangles, return_inverse=True)  # the vertices a triangle uses
    triangles = triangles.reshape(-1, 3)
    if normals is not None:
        lengths = np.linalg.norm(normals[used], axis=1)
        if np.any(lengths < 1e-6):
            element = int(used[np.argmax(lengths < 1e-6)])
            fail("normals", f"element {element} is {normals[element].tolist()}: a normal must have a length")
        normals = normals[used] / lengths[:, None]
    positions, texcoords, colors = (None if a is None else a[used] for a in (positions, texcoords, colors))
    if normals is None:
        positions, normals, triangles, texcoords, colors = crease_normals(positions, triangles, texcoords, colors)
    return Mesh(positions.astype(np.float32), normals.astype(np.float32), triangles.astype(np.uint32),
                None if texcoords is None else texcoords.astype(np.float32),
                colors=None if colors is None else colors.astype(np.float32))


def _vertex_array(value, argument, widths, count, fail):
    """`value` as a float64 (count, width) array, `width` one of `widths` (or `widths` itself),
    each component finite and within the limits; count None: any number of rows but 0."""
    try:
        array = np.asarray(value, np.float64)
    except (TypeError, ValueError):
        fail(argument, "must be an array of numbers")
    widths = widths if isinstance(widths, tuple) else (widths,)
    if array.ndim != 2 or array.shape[1] not in widths or len(array) == 0:
        shapes = " or ".join(f"(N, {width})" for width in widths)
        fail(argument, f"must have shape {shapes} with N at least 1, got {array.shape}")
    if count is not None and len(array) != count:
        fail(argument, f"has {len(array)} elements, positions {count}")
    check_vertices(array, lambda message: fail(argument, message))
    return array


def _triangles(indices, count, fail):
    """`indices` as an int64 (T, 3) array of vertex numbers below `count`."""
    try:
        array = np.asarray(indices)
    except (TypeError, ValueError):
        array = np.array(None)
    if not np.issubdtype(array.dtype, np.integer) or array.size == 0 or array.size % 3:
        fail("indices", "must be whole numbers, three per triangle (shape (T, 3))")
    triangles = array.reshape(-1, 3).astype(np.int64)
    if triangles.min() < 0 or triangles.max() >= count:
        fail("indices", f"must be vertex numbers 0..{count - 1}, got {int(triangles.min())}..{int(triangles.max())}")
    return triangles


# ---- the limits of loaded scenes ----------------------------------------------------------

def check_scene(scene):
    """Hold `scene` to the limits a loaded scene is held to (engine/core/limits.py): nodes nested
    at most MAX_DEPTH levels below the root; every node's world transform and what it places
    (check_placement); every material's fields within their ranges (check_material); every
    mesh's vertex data finite and within +-1e6, its indices within its vertices, texture
    coordinates where its material has textures and tangents where it has a normal texture.
    Raises SceneError naming the node and the field (`scene "demo": node "ball".scale: ...`);
    returns the scene."""
    if not isinstance(scene, Scene):
        raise VctError(f"must be an engine.Scene, got {type(scene).__name__}", field="scene")
    where = f'scene "{scene.name}"'

    def fail(field, message):
        raise SceneError(message, source=where, field=field)

    stack = [(scene.root, np.eye(4), 0, "root")]
    while stack:
        node, parent_world, level, field = stack.pop()
        if not isinstance(node, Node):
            fail(field, f"must be an engine.Node, got {type(node).__name__}")
        field = f'node "{node.name}"'
        if level > MAX_DEPTH:
            fail(field, f"nests more than {MAX_DEPTH} levels below the root")
        if node.material is not None:
            check_material(node.material, lambda name, message: fail(f'{field}.material "{node.material.name}".{name}',
                                                                     message), {})
        if node.mesh is not None:
            _check_mesh(node.mesh, node.material, lambda name, message: fail(f"{field}.mesh.{name}", message))
        world = parent_world @ node.local_matrix()
        check_placement(node, world, lambda attribute, message: fail(f"{field}.{attribute}" if attribute else field,
                                                                     message))
        stack.extend((child, world, level + 1, f"{field}.children[{i}]")
                     for i, child in reversed(list(enumerate(node.children))))
    return scene


def _check_mesh(mesh, material, fail):
    """A Mesh's arrays: shapes, finite values within the limits, indices within the vertices,
    and what its material's textures need."""
    widths = {"positions": 3, "normals": 3, "texcoords": 2, "tangents": 4, "colors": 3, "texcoords1": 2}
    count = len(mesh.positions)
    for name, width in widths.items():
        array = getattr(mesh, name)
        if array is None:
            continue
        array = np.asarray(array)
        if array.ndim != 2 or array.shape != (count, width):
            fail(name, f"must have shape ({count}, {width}) (one row per position), got {array.shape}")
        check_vertices(array.astype(np.float64), lambda message: fail(name, message))
    indices = np.asarray(mesh.indices)
    if indices.ndim != 2 or indices.shape[1] != 3 or not np.issubdtype(indices.dtype, np.integer) or len(indices) == 0:
        fail("indices", f"must be whole numbers of shape (T, 3), got {indices.dtype} {indices.shape}")
    if indices.min() < 0 or indices.max() >= count:
        fail("indices", f"must be vertex numbers 0..{count - 1}, got {int(indices.min())}..{int(indices.max())}")
    if material is None:
        return
    for texture_field in (name for name in TEXTURE_FIELDS if getattr(material, name) is not None):
        uv_set = material.uv_sets.get(texture_field, 0)
        if (mesh.texcoords, mesh.texcoords1)[uv_set] is None:
            fail("texcoords" if uv_set == 0 else "texcoords1",
                 f'material "{material.name}" has a {texture_field} on texture coordinate set {uv_set}, which the '
                 "mesh does not have")
    if material.normal_texture is not None and mesh.tangents is None:
        fail("tangents", f'material "{material.name}" has a normal_texture: the mesh needs tangents')


# ---- trimesh ----------------------------------------------------------------------------------

def from_trimesh(scene_or_mesh, name=None):
    """The engine Scene of a trimesh.Trimesh or trimesh.Scene (see the module docstring for
    what is read and how), named `name` (default "trimesh"). It has no light until one is
    added. Raises VctError naming the argument, or SceneError naming the trimesh element."""
    import trimesh

    if name is not None and not isinstance(name, str):
        raise VctError(f"must be a string or None, got {type(name).__name__}", field="name")
    if isinstance(scene_or_mesh, trimesh.Trimesh):
        scene_or_mesh = trimesh.Scene(scene_or_mesh)
    if not isinstance(scene_or_mesh, trimesh.Scene):
        raise VctError(f"must be a trimesh.Trimesh or trimesh.Scene, got {type(scene_or_mesh).__name__}",
                       field="scene_or_mesh")
    return _TrimeshScene(scene_or_mesh, name or "trimesh").scene()


class _TrimeshScene:
    """One trimesh.Scene being converted: its geometry and materials, each converted once, and
    its images within one scene's image limits."""

    def __init__(self, source, name):
        self.source = source
        self.name = name
        self.where = f'trimesh scene "{name}"'
        self.parts = {}      # geometry name -> (Mesh or None, Material)
        self.materials = {}  # id of a trimesh material (the scene holds each while it is read) -> its Material
        self.textures = FileTextures(InputFiles())
        self.grey = default_material()
        self.coloured = Material(name="vertex colours", albedo=np.ones(3))

    def fail(self, field, message):
        raise SceneError(message, source=self.where, field=field)

    def scene(self):
        graph = self.source.graph
        children = graph.transforms.children
        camera_name = self.source.camera.name if self.source.has_camera else None
        camera_node = None
        root = Node(name=self.name)
        stack = [(root, graph.base_frame, child, 1) for child in reversed(children.get(graph.base_frame, []))]
        while stack:
            parent, parent_frame, frame, level = stack.pop()
            if level > MAX_DEPTH:
                self.fail(f'node "{frame}"', f"nests more than {MAX_DEPTH} levels deep")
            node = self.node(frame, *graph.get(frame_to=frame, frame_from=parent_frame))
            if frame == camera_name:
                node.camera, camera_node = self.camera(), node
            parent.children.append(node)
            stack.extend((node, frame, child, level + 1) for child in reversed(children.get(frame, [])))
        scene = Scene(name=self.name, root=root, camera=None)
        if not any(n.mesh is not None for n, _ in root.walk()):
            self.fail("", "holds no triangles")
        if camera_node is not None:
            world = next(m for n, m in scene.cameras() if n is camera_node)
            scene.camera = camera_node.camera.placed(world, *(int(v) for v in self.source.camera.resolution))
        else:
            scene.camera = framing_camera(scene.bounds(), DEFAULT_WIDTH, round(DEFAULT_WIDTH / FALLBACK_ASPECT))
        return check_scene(scene)

    def node(self, graph_node, matrix, geometry):
        """The Node of a graph node with its local `matrix` and the name of the geometry it
        places (None: none)."""
        field = f'node "{graph_node}"'
        trs = decompose(matrix)
        if trs is None:
            self.fail(f"{field}.matrix", "is not a translation, rotation and scale (it shears or projects), "
                                         "which are all a node holds")
        node = Node(name=str(graph_node))
        node.translation, node.rotation_deg, node.scale = trs
        if geometry is not None:
            node.mesh, node.material = self.part(geometry)
        return node

    def camera(self):
        camera = self.source.camera
        fov = float(camera.fov[1])
        if not MIN_FOV_DEG <= fov <= MAX_FOV_DEG:
            self.fail(f'camera "{camera.name}".fov', f"the vertical field of view must be within "
                                                    f"{MIN_FOV_DEG:g}..{MAX_FOV_DEG:g} degrees, got {fov:g}")
        width, height = (int(v) for v in camera.resolution)
        return NodeCamera(name=str(camera.name), vertical_fov_deg=fov, aspect_ratio=width / height)

    # -- geometry

    def part(self, geometry):
        """(Mesh, Material) of a geometry of the scene, made once; Mesh None where no triangle
        has an area."""
        if geometry not in self.parts:
            self.parts[geometry] = self.convert(geometry)
        return self.parts[geometry]

    def convert(self, geometry):
        """(Mesh, Material) of a geometry: its arrays checked in trimesh's numbering, its
        vertices split as its colours and normals need (see the module docstring)."""
        import trimesh

        field = f'geometry "{geometry}"'
        mesh = self.source.geometry[geometry]
        if not isinstance(mesh, trimesh.Trimesh):
            self.fail(field, f"is a {type(mesh).__name__}: only triangle meshes (trimesh.Trimesh) are drawn")
        visual = mesh.visual
        names = {"positions": "vertices", "indices": "faces", "normals": "vertex_normals", "texcoords": "visual.uv",
                 "colors": "visual.face_colors" if visual.kind == "face" else "visual.vertex_colors"}

        def fail(argument, message):
            self.fail(f"{field}.{names[argument]}", message)

        colors = None
        if visual.kind == "vertex":
            colors = visual.vertex_colors[:, :3] / 255.0
        elif visual.kind == "texture" and "color" in visual.vertex_attributes:
            colors = np.asarray(visual.vertex_attributes["color"])[:, :3] / 255.0
        material = self.material(visual.material, geometry) if hasattr(visual, "material") else None
        if material is None:
            material = self.coloured if colors is not None or visual.kind == "face" else self.grey
        texcoords = None
        if getattr(visual, "uv", None) is not None and len(visual.uv) == len(mesh.vertices):
            uv = _vertex_array(np.asarray(visual.uv)[:, :2], "texcoords", 2, None, fail)
            texcoords = np.column_stack([uv[:, 0], 1.0 - uv[:, 1]])
        if material.textures() and texcoords is None:
            self.fail(field, f'material "{material.name}" has textures but the mesh has no texture coordinates (visual.uv)')
        if len(mesh.faces) == 0:
            return None, material
        positions = _vertex_array(mesh.vertices, "positions", 3, None, fail)
        triangles = _triangles(mesh.faces, len(positions), fail)
        held = "vertex_normals" in mesh._cache  # the test trimesh's glTF export makes
        normals = _vertex_array(mesh.vertex_normals, "normals", 3, len(positions), fail) if held else None
        if visual.kind == "face":  # every face its own three vertices, in its colour
            corners = triangles.reshape(-1)
            positions, triangles = positions[corners], np.arange(len(corners)).reshape(-1, 3)
            normals, texcoords = (None if a is None else a[corners] for a in (normals, texcoords))
            colors = np.repeat(visual.face_colors[:, :3] / 255.0, 3, axis=0)
        part = _mesh(positions, triangles, normals, texcoords, colors, fail)
        if part is not None and material.normal_texture is not None:
            part.tangents = generate_tangents(part.positions, part.normals, part.texcoords, part.indices)
        return part, material

    # -- materials and textures

    def material(self, source, geometry):
        """The Material of the trimesh PBRMaterial or SimpleMaterial of `geometry` (named after
        it where the material has no name), made once per object and held to the material
        limits, each field named as trimesh names it."""
        from trimesh.visual.material import PBRMaterial, SimpleMaterial

        if id(source) in self.materials:
            return self.materials[id(source)]
        field = f'geometry "{geometry}".visual.material'
        name = source.name if isinstance(source.name, str) else str(geometry)
        if isinstance(source, PBRMaterial):
            material, fields = self.pbr_material(source, name, field), PBR_FIELDS
        elif isinstance(source, SimpleMaterial):
            material, fields = self.simple_material(source, name, field), SIMPLE_FIELDS
        else:
            self.fail(field, f"is a {type(source).__name__}: a PBRMaterial or SimpleMaterial is read")
        check_material(material, lambda name, message: self.fail(f"{field}.{name}", message), fields)
        self.materials[id(source)] = material
        return material

    def pbr_material(self, source, name, field):
        base_color = np.ones(4) if source.baseColorFactor is None else np.asarray(source.baseColorFactor) / 255.0
        alpha_mode = source.alphaMode or "OPAQUE"
        return Material(
            name=name,
            albedo=base_color[:3],
            alpha=float(base_color[3]),
            metalness=1.0 if source.metallicFactor is None else float(source.metallicFactor),
            roughness=1.0 if source.roughnessFactor is None else float(source.roughnessFactor),
            specular=0.04,
            emission=np.zeros(3) if source.emissiveFactor is None else np.asarray(source.emissiveFactor, np.float64),
            alpha_mode=alpha_mode,
            alpha_cutoff=source.alphaCutoff if alpha_mode == "MASK" and source.alphaCutoff is not None else 0.5,
            double_sided=bool(source.doubleSided),
            **{key: self.texture(getattr(source, attribute), f"{field}.{attribute}", srgb)
               for key, (attribute, srgb) in PBR_TEXTURES.items()})

    def simple_material(self, source, name, field):
        diffuse = np.asarray(source.diffuse, np.float64) / 255.0
        return Material(
            name=name,
            albedo=diffuse[:3],
            alpha=float(diffuse[3]),
            alpha_mode="BLEND" if diffuse[3] < 1.0 else "OPAQUE",
            roughness=(2.0 / (source.glossiness + 2.0)) ** 0.25,
            specular=0.04 if np.any(np.asarray(source.specular)[:3] > 0) else 0.0,
            base_color_texture=self.texture(source.image, f"{field}.image", srgb=True))

    def texture(self, image, field, srgb):
        """The Texture of a PIL image (None: none), held to the image limits: encoded as PNG and
        decoded as the loaders decode images, so the same pixels are one Texture."""
        from PIL import Image

        if image is None:
            return None
        if not isinstance(image, Image.Image):
            self.fail(field, f"must be a PIL image, got {type(image).__name__}")
        if image.mode == "I":  # 32-bit grey: as 16-bit, whose high byte the loaders keep
            image = image.convert("I;16")
        elif image.mode not in PNG_MODES:
            try:
                image = image.convert("RGBA" if "A" in image.mode else "RGB")
            except ValueError:
                self.fail(field, f"is an image of mode {image.mode}, which vct does not read")
        encoded = io.BytesIO()
        image.save(encoded, format="PNG", compress_level=0)
        try:
            key, _ = self.textures.decoded(encoded.getvalue())
        except ValueError as exc:
            self.fail(field, str(exc))
        return self.textures.texture(key, f"{self.where}: {field}", srgb, "REPEAT", "REPEAT")
