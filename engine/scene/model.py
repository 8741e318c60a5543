"""The scene model: nodes, transforms, meshes, materials, lights, camera. Plain Python and
numpy, no GL: the renderer uploads what it needs, and an edit (a moved light, a new albedo)
shows on the next frame.

Edits are found without walking the scene: every Node, Mesh, Material, Light and NodeCamera
records itself in the edit log (`EDITS`) whenever one of its fields is set after it was made,
or one of its small arrays (a node's transform, a light's position, a material's albedo) is
written into (`node.translation += step`, `light.position[:] = p`: TrackedArray), and a node
whenever its list of children changes. A mesh's arrays are read-only: a geometry edit assigns
a new array."""
import collections
import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..core import transforms
from ..core.errors import VctError
from .animation import NodeTracks


WRAP_MODES = ("REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT")
ALPHA_MODES = ("OPAQUE", "MASK", "BLEND")
TEXTURE_FIELDS = ("base_color_texture", "metallic_roughness_texture", "emissive_texture", "normal_texture")
IDENTITY_UV = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))


class EditLog:
    """The scene model's objects edited after they were made, each once, in the order of their
    latest edit, with the log's serial number at that edit: a reader keeps the serial it read
    up to and asks for what was edited since (the renderer does, each frame), at a cost that
    grows with the objects edited, not with the scene. Objects are held weakly: one dropped
    leaves the log."""

    def __init__(self):
        self.serial = 0
        self.shape_edits = 0  # edits of a scene graph's shape (STRUCTURE_FIELDS, a node's children)
        self._latest = collections.OrderedDict()  # id(object) -> (serial of its latest edit, weak reference)
        self._dropped = []                        # (id, reference) of objects gone, to take out of _latest

    def record(self, obj, shape=False):
        """Log an edit of `obj`; `shape`: one of the scene graph's shape."""
        self.serial += 1
        self.shape_edits += shape
        self._purge()
        key = id(obj)
        entry = self._latest.pop(key, None)
        if entry is None or entry[1]() is not obj:
            entry = (0, weakref.ref(obj, lambda ref, key=key: self._dropped.append((key, ref))))
        self._latest[key] = (self.serial, entry[1])

    def since(self, serial):
        """The objects edited after log serial `serial`, the latest edit first."""
        self._purge()
        edited = []
        for key in reversed(self._latest):
            edit_serial, ref = self._latest[key]
            if edit_serial <= serial:
                break
            obj = ref()
            if obj is not None:
                edited.append(obj)
        return edited

    def _purge(self):
        while self._dropped:
            key, ref = self._dropped.pop()
            entry = self._latest.get(key)
            if entry is not None and entry[1] is ref:
                del self._latest[key]


EDITS = EditLog()
# The fields whose edits change the scene graph's shape (a node's children, mesh, light, camera
# or animation given or taken): what a scene caches about its shape is kept while
# EDITS.shape_edits is unchanged.
STRUCTURE_FIELDS = frozenset({"children", "mesh", "light", "camera", "animation", "skin"})


class TrackedArray(np.ndarray):
    """A scene-model object's small array (float64): writing into it, by item assignment or an
    in-place operation, records its owner in EDITS as setting the field does. What is computed
    from it is a plain array."""

    def __array_finalize__(self, obj):
        self._owner = getattr(obj, "_owner", None)  # a weak reference to the object holding it (views share it)

    def __setitem__(self, key, value):
        super().__setitem__(key, value)
        self._written()

    def __array_ufunc__(self, ufunc, method, *inputs, out=None, **kwargs):
        plain = [np.asarray(value) if isinstance(value, TrackedArray) else value for value in inputs]
        if out is not None:
            kwargs["out"] = tuple(np.asarray(value) if isinstance(value, TrackedArray) else value for value in out)
        result = getattr(ufunc, method)(*plain, **kwargs)
        if out is None:
            return result
        for value in out:
            if isinstance(value, TrackedArray):
                value._written()
        return out[0] if len(out) == 1 else out

    def __repr__(self):
        return repr(np.asarray(self))

    def _written(self):
        owner = self._owner() if self._owner is not None else None
        if owner is not None and owner.__dict__.get("_tracked"):
            EDITS.record(owner)


def tracked_array(value, owner):
    """A TrackedArray copy of `value` (float64) that records `owner` when written into."""
    array = np.array(value, dtype=float).view(TrackedArray)
    array._owner = weakref.ref(owner)
    return array


class Tracked:
    """A scene-model object whose every field set after construction is recorded in EDITS
    (`_ARRAYS`: its array fields, held as TrackedArray copies that record it when written into)."""

    _ARRAYS = frozenset()

    def __setattr__(self, name, value):
        if name in self._ARRAYS and value is not None:
            value = tracked_array(value, self)
        object.__setattr__(self, name, value)
        if self.__dict__.get("_tracked"):
            EDITS.record(self, shape=name in STRUCTURE_FIELDS)

    def __post_init__(self):
        object.__setattr__(self, "_tracked", True)

    def __setstate__(self, state):
        """A copy (copy.copy, copy.deepcopy) owns arrays of its own."""
        self.__dict__.update(state)
        for name in self._ARRAYS:
            if state.get(name) is not None:
                object.__setattr__(self, name, tracked_array(state[name], self))


class Children(list):
    """A node's children: a list that records its node in EDITS whenever it changes."""

    def __init__(self, items=(), owner=None):
        super().__init__(items)
        self.owner = owner

    def _changed(self):
        owner = getattr(self, "owner", None)
        if owner is not None and owner.__dict__.get("_tracked"):
            EDITS.record(owner, shape=True)


def _recording(name):
    method = getattr(list, name)

    def edit(self, *args):
        result = method(self, *args)
        self._changed()
        return self if name in ("__iadd__", "__imul__") else result
    edit.__name__ = name
    return edit


for _name in ("append", "extend", "insert", "remove", "pop", "clear", "sort", "reverse", "__setitem__", "__delitem__",
              "__iadd__", "__imul__"):
    setattr(Children, _name, _recording(_name))


@dataclass(frozen=True, eq=False)
class Texture:
    """An image a material samples. Immutable and compared by identity: materials that use the
    same image the same way hold the same Texture object (upload it once), and copies of a
    material (copy.deepcopy) share it too.

    `image` is uint8 (H, W, C) with C = 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA), row 0 =
    the image's top row, read-only. Texture coordinates follow glTF: (0, 0) is the image's
    top-left corner and v grows downwards, so uploading the rows in this order and sampling at
    (u, v) shows it the right way up. `srgb`: the values are sRGB-encoded colour (base colour,
    emission), to be decoded to linear when sampled; otherwise they are linear data
    (metal-roughness, normals). `wrap_s`/`wrap_t` (along u/v): one of WRAP_MODES, GL's names.
    `name` says where the image came from, for messages (e.g. `sponza.glb: images[3]`)."""

    name: str
    image: np.ndarray
    srgb: bool
    wrap_s: str = "REPEAT"
    wrap_t: str = "REPEAT"

    def __post_init__(self):
        self.image.flags.writeable = False

    def __deepcopy__(self, memo):
        return self


@dataclass
class Material(Tracked):
    """The renderer's material: a base colour `albedo` (linear RGB, at most 1), `roughness`
    (perceptual, 0..1: Blinn-Phong exponent 2/r^4 - 2), `metalness` (0..1), `specular` (F0, the
    reflectance at normal incidence of the dielectric part; 0 = Lambertian) and `emission`
    (radiance W/(m^2 sr), front side), each optionally multiplied by a texture:

    - `base_color_texture` (sRGB): RGB x albedo, and its alpha (where it has one) x `alpha`;
    - `metallic_roughness_texture` (linear): G x roughness, B x metalness (glTF's channels);
    - `emissive_texture` (sRGB): RGB x emission;
    - `normal_texture` (linear): a tangent-space normal map (RGB = 0.5 n + 0.5, +y towards the
      image's top, as glTF), its x and y multiplied by `normal_scale`; the mesh has tangents.

    `alpha` is the base-colour alpha factor. `alpha_mode`: OPAQUE ignores alpha; MASK cuts out
    where alpha < `alpha_cutoff`; BLEND (partial transparency) is drawn over what lies behind
    it, covering alpha of it (engine/passes/transparent.py), and stops alpha of the light that
    crosses it in the shadow maps and the voxels (each of its texels and voxels dissolved with
    probability 1 - alpha). `double_sided`: back faces are drawn too (with the normal
    flipped), as glTF's doubleSided; otherwise they may be culled.

    Materials from glTF files (metallic-roughness), field by field: albedo, alpha =
    pbrMetallicRoughness.baseColorFactor (RGB, A); base_color_texture = baseColorTexture;
    metalness, roughness = metallicFactor, roughnessFactor; metallic_roughness_texture =
    metallicRoughnessTexture; specular = 0.04 (glTF's dielectric F0, IOR 1.5); emission =
    emissiveFactor x KHR_materials_emissive_strength.emissiveStrength, taken as radiance in
    W/(m^2 sr); emissive_texture = emissiveTexture; normal_texture, normal_scale =
    normalTexture and its scale; alpha_mode, alpha_cutoff, double_sided = alphaMode,
    alphaCutoff (MASK's), doubleSided; uv_sets, uv_transforms = each textureInfo's
    texCoord and KHR_texture_transform (offset, rotation, scale, texCoord). A mesh's COLOR_0
    (RGB; its alpha is not read) multiplies the base colour (Mesh.colors). occlusionTexture is
    not read: the cone-traced occlusion replaces it. From OBJ/MTL files: see
    engine/formats/mesh_files.py."""

    name: str
    albedo: np.ndarray = field(default_factory=lambda: np.array([0.8, 0.8, 0.8]))
    roughness: float = 1.0
    metalness: float = 0.0
    specular: float = 0.0  # dielectric reflectance at normal incidence (F0); 0 = Lambertian
    emission: np.ndarray = field(default_factory=lambda: np.zeros(3))  # radiance, front side
    alpha: float = 1.0
    alpha_mode: str = "OPAQUE"  # one of ALPHA_MODES
    alpha_cutoff: float = 0.5
    double_sided: bool = False
    base_color_texture: Texture = None
    metallic_roughness_texture: Texture = None
    emissive_texture: Texture = None
    normal_texture: Texture = None
    normal_scale: float = 1.0
    # Per texture field (base_color_texture, ...): the texture coordinate set it reads (0 or 1,
    # default 0) and the 2x3 matrix applied to (u, v, 1) before sampling (KHR_texture_transform;
    # default identity).
    uv_sets: dict = field(default_factory=dict)
    uv_transforms: dict = field(default_factory=dict)

    _ARRAYS = frozenset({"albedo", "emission"})

    @property
    def alpha_tested(self):
        """Whether its alpha cuts out (MASK) or dissolves (BLEND) shadow texels and voxels."""
        return self.alpha_mode in ("MASK", "BLEND")

    def textures(self):
        """The textures this material uses, in field order."""
        return [getattr(self, name) for name in TEXTURE_FIELDS if getattr(self, name) is not None]

    def uv_transform(self, texture_field):
        """The 2x3 matrix a texture's coordinates go through (identity by default)."""
        return self.uv_transforms.get(texture_field, IDENTITY_UV)


@dataclass
class Mesh(Tracked):
    """Triangles in the node's local frame: positions (V,3), normals (V,3), indices (T,3), and
    optionally texcoords (V,2) (glTF's convention: (0, 0) is the image's top-left and v grows
    downwards; see Texture) and tangents (V,4): xyz along +u, w = +-1 the handedness, so that
    the bitangent w * cross(normal, tangent.xyz) points towards the image's top (the glTF /
    MikkTSpace convention that normal maps' green channel follows). Meshes read from files
    hold float32 vertex data and uint32 indices.

    Every array is made read-only when it is set: the renderer notices a geometry edit by the
    identity of the arrays, so an edit replaces an array (`mesh.positions = new`) instead of
    writing into it."""

    positions: np.ndarray
    normals: np.ndarray
    indices: np.ndarray
    texcoords: np.ndarray = None
    tangents: np.ndarray = None
    colors: np.ndarray = None      # (V, 3) linear RGB that multiplies the base colour (glTF COLOR_0)
    texcoords1: np.ndarray = None  # (V, 2) a second set of texture coordinates (glTF TEXCOORD_1)
    # A skin's influences (glTF JOINTS_n, WEIGHTS_n): (V, 4 k) joint indices into the Skin of the
    # node drawing the mesh, and their weights, which sum to 1 per vertex.
    joints: np.ndarray = None
    weights: np.ndarray = None
    targets: tuple = ()  # MorphTargets: displacements blended by the node's weights
    target_weights: np.ndarray = None  # the weights of a node that gives none (glTF mesh.weights; None: zeros)

    def __setattr__(self, name, value):
        if isinstance(value, np.ndarray):  # read-only as it is: a mesh's arrays may be large
            value.flags.writeable = False
        super().__setattr__(name, value)

    def arrays(self):
        """The arrays the mesh is made of: the same objects mean the same geometry."""
        return (self.positions, self.normals, self.indices, self.texcoords, self.tangents, self.colors, self.texcoords1,
                self.joints, self.weights, self.targets)

    @property
    def posed(self):
        """Whether a node's pose moves its vertices (a skin or morph targets)."""
        return self.joints is not None or bool(self.targets)

    def bounds(self, matrix):
        p = transforms.transform_points(matrix, self.positions)
        return p.min(axis=0), p.max(axis=0)


@dataclass(frozen=True, eq=False)
class MorphTarget:
    """Displacements of every vertex of a mesh (glTF morph target), (V, 3) each, None where the
    target leaves that attribute: added to the mesh's positions, normals and tangents' xyz
    times the node's weight for the target."""
    positions: np.ndarray = None
    normals: np.ndarray = None
    tangents: np.ndarray = None


@dataclass(eq=False)
class Skin:
    """The joints that pose a skinned mesh (glTF skin): joint nodes of the scene, each with the
    inverse of its bind matrix (J, 4, 4). A vertex is posed in the world as
    sum_i w_i J_i v, J_i = world(joint_i) inverse_bind_i (glTF 2.0, 3.7.3.3): the transform of
    the node drawing the mesh does not apply."""
    joints: list
    inverse_bind_matrices: np.ndarray
    name: str = "skin"


@dataclass
class Light(Tracked):
    type: str  # point | spot | directional
    intensity: np.ndarray  # point/spot: radiant intensity W/sr; directional: irradiance W/m^2
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    direction: np.ndarray = field(default_factory=lambda: np.array([0.0, -1.0, 0.0]))
    range: float = 0.0  # 0: pure inverse square, no cut-off
    inner_angle_deg: float = 30.0  # spot: full intensity inside
    outer_angle_deg: float = 45.0  # spot: zero outside
    cast_shadows: bool = True

    _ARRAYS = frozenset({"intensity", "position", "direction"})

    def placed(self, world):
        """The light in world space, carried by a node of world matrix `world`: its position
        moved, its direction turned and made unit length again (kept where it turns to zero)."""
        position = transforms.transform_points(world, [self.position])[0]
        direction = world[:3, :3] @ self.direction
        norm = np.linalg.norm(direction)
        return Light(self.type, np.asarray(self.intensity, float), position, direction / norm if norm > 0 else self.direction,
                     self.range, self.inner_angle_deg, self.outer_angle_deg, self.cast_shadows)


@dataclass
class Camera:
    """The camera an image is rendered from: perspective (`vertical_fov_deg`) or orthographic
    (`half_height`: half the view's height in metres; its width follows the image's aspect)."""

    position: np.ndarray
    look_at: np.ndarray
    up: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0, 0.0]))
    vertical_fov_deg: float = 60.0  # degrees; these defaults are the scene format's
    width: int = 256
    height: int = 256
    projection: str = "perspective"  # or "orthographic"
    half_height: float = 1.0
    name: str = "camera"

    def __post_init__(self):
        self.position, self.look_at, self.up = (np.asarray(v, float) for v in (self.position, self.look_at, self.up))

    def view_matrix(self):
        return transforms.look_at(self.position, self.look_at, self.up)

    def projection_matrix(self, aspect, near, far):
        if self.projection == "orthographic":
            return transforms.orthographic(self.half_height * aspect, self.half_height, near, far)
        return transforms.perspective(self.vertical_fov_deg, aspect, near, far)


@dataclass
class NodeCamera(Tracked):
    """A camera a node carries (a glTF camera): it looks along the node's -z with +y up.
    Perspective: `vertical_fov_deg`; orthographic: `half_height` (and `half_width`);
    `aspect_ratio` the image's width / height it was made for (None: not given)."""

    name: str
    projection: str = "perspective"
    vertical_fov_deg: float = 60.0
    half_height: float = 1.0
    aspect_ratio: float = None

    def placed(self, world, width, height):
        """The Camera of this node under world matrix `world`, for an image of width x height."""
        position = world[:3, 3].copy()
        forward = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
        up = world[:3, :3] @ np.array([0.0, 1.0, 0.0])
        return Camera(position=position, look_at=position + forward / np.linalg.norm(forward), up=up / np.linalg.norm(up),
                      vertical_fov_deg=self.vertical_fov_deg, width=width, height=height, projection=self.projection,
                      half_height=self.half_height, name=self.name)


@dataclass
class Node(Tracked):
    """A named node of the scene graph with a local transform (T * R * S)."""

    name: str
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation_deg: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: np.ndarray = field(default_factory=lambda: np.ones(3))
    mesh: Mesh = None
    material: Material = None
    light: Light = None
    camera: NodeCamera = None
    children: list = field(default_factory=list)
    animation: NodeTracks = None  # what animates it (engine.scene.animation), None: it keeps its pose
    skin: Skin = None  # the joints posing its mesh (a skinned mesh)
    morph_weights: np.ndarray = None  # its mesh's morph target weights (None: the mesh's target_weights)

    _ARRAYS = frozenset({"translation", "rotation_deg", "scale", "morph_weights"})

    def __setattr__(self, name, value):
        if name == "children" and not (isinstance(value, Children) and value.owner is self):
            value = Children(value, owner=self)
        super().__setattr__(name, value)

    def local_matrix(self):
        return transforms.compose(self.translation, self.rotation_deg, self.scale)

    def walk(self, parent=np.eye(4)):
        """Yield (node, world_matrix) depth first."""
        world = parent @ self.local_matrix()
        yield self, world
        for child in self.children:
            yield from child.walk(world)

    def nodes(self):
        """Yield this node and every node below it, depth first."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node.children))

    def find(self, name):
        return next((node for node, _ in self.walk() if node.name == name), None)


@dataclass
class VoxelRegion:
    """The cube one voxel grid spans."""
    center: np.ndarray
    size: float


@dataclass(frozen=True)
class Clipmap:
    """Voxel levels around the camera for scenes larger than one grid: `levels` cubes of
    `resolution`^3 voxels, level k's voxels 2^k `voxel_size` wide, each twice as large as the
    one inside it (engine/voxels/clipmap.py places them)."""
    levels: int
    resolution: int
    voxel_size: float


@dataclass(eq=False)
class Environment:
    """The light that comes from beyond the scene: a sky of uniform `radiance` (W/(m^2 sr),
    RGB), or an equirectangular `image` of linear radiance (H, W, 3) float32, read-only, row 0
    at the top, times `scale`. Direction d (world space, turned by -rotation_y_deg about +y
    into the image's frame) maps to u = atan2(d.x, -d.z) / (2 pi) (wrapped into [0, 1): the
    left edge looks along -z, a quarter across along +x), v = acos(d.y) / pi (the top row looks
    straight up): Mitsuba's `envmap` with `to_world` a rotation of rotation_y_deg about +y.
    `name` says where the image came from, for messages."""

    radiance: np.ndarray = field(default_factory=lambda: np.ones(3))
    image: np.ndarray = None
    scale: float = 1.0
    rotation_y_deg: float = 0.0
    name: str = "environment"

    def __setattr__(self, name, value):
        if isinstance(value, np.ndarray) and name == "image":
            value.flags.writeable = False
        super().__setattr__(name, value)

    def rotation(self):
        """3x3 matrix turning world directions into the image's frame."""
        return transforms.rotate_euler_deg([0.0, -self.rotation_y_deg, 0.0])[:3, :3]


STUDIO_SIZE = (64, 32)  # the studio sky's image, width x height


def studio_environment():
    """The sky vct's commands show a scene under where nothing lights it, as model viewers do:
    a neutral grey studio whose radiance grows with the direction's height, L = 0.6 + 0.4 d.y
    (1.0 straight up, 0.6 at the horizon, 0.2 straight down, W/(m^2 sr)), so a face turned up
    takes E = 0.87 pi and one turned down 0.33 pi. An equirectangular image (a row per v)."""
    width, height = STUDIO_SIZE
    up = np.cos(np.pi * (np.arange(height) + 0.5) / height)  # d.y at each row's centre: v = acos(d.y) / pi
    image = np.repeat((0.6 + 0.4 * up)[:, None, None], width, axis=1).repeat(3, axis=2).astype(np.float32)
    return Environment(image=image, name="studio sky")


@dataclass
class Scene:
    name: str
    root: Node
    camera: Camera
    materials: dict = field(default_factory=dict)  # a scene file's materials by name
    voxel_region: VoxelRegion = None  # None: derived from the geometry's bounds
    clipmap: Clipmap = None           # levels around the camera instead of one grid over voxel_region
    environment: Environment = None   # None: black beyond the scene
    source: str = None
    files: tuple = ()  # every file the scene was read from (resolved paths): outputs must not overwrite one
    camera_node: Node = None  # the camera node `camera` was placed from (None: the scene file's camera)

    _shape: tuple = field(default=None, init=False, repr=False, compare=False)  # see _animated_nodes

    def _animated_nodes(self):
        """(the animated nodes in the order they come, the path of nodes from the root to the
        camera node), found again only after an edit of the graph's shape."""
        key = (EDITS.shape_edits, id(self.root), id(self.camera_node))
        if self._shape is None or self._shape[0] != key:
            animated = [node for node in self.root.nodes() if node.animation is not None]
            path = _path_to(self.root, self.camera_node) if self.camera_node is not None else None
            self._shape = (key, animated, path)
        return self._shape[1], self._shape[2]

    def animations(self):
        """{name: duration in seconds} of the animations the scene's nodes play (their last
        keyframe), in the order the nodes come."""
        durations = {}
        for node in self._animated_nodes()[0]:
            for name, duration in node.animation.durations().items():
                durations[name] = max(durations.get(name, 0.0), duration)
        return durations

    def played(self, animation=None, field="animation", source=None):
        """{name: duration} of the animations `animation` plays (a name of `animations()`;
        None: all of them). VctError naming `field` (and `source`) for a name the scene has not."""
        durations = self.animations()
        if animation is None:
            return durations
        if animation not in durations:
            names = ", ".join(f'"{name}"' for name in durations) or "none"
            raise VctError(f'no animation named "{animation}" (the scene has: {names})', source=source, field=field)
        return {animation: durations[animation]}

    def pose_at(self, t, animation=None):
        """Pose the scene at `t` seconds, in place: every animated node takes its translation,
        rotation, scale and morph weights at t of `animation` (a name of `animations()`; None: all of them
        together), looping over the longest of them; a camera placed from a camera node
        follows the node. Returns the scene."""
        durations = self.played(animation)
        names = list(durations)
        longest = max(durations.values(), default=0.0)
        local_t = float(t) % longest if longest > 0.0 else 0.0
        animated, camera_path = self._animated_nodes()
        for node in animated:
            node.translation, node.rotation_deg, node.scale, weights = node.animation.pose(local_t, names)
            if weights is not None:
                node.morph_weights = weights
        if self.camera_node is not None:
            world = np.eye(4)
            for node in camera_path:
                world = world @ node.local_matrix()
            placed = self.camera_node.camera.placed(world, self.camera.width, self.camera.height)
            placed.name = self.camera.name
            self.camera = placed
        return self

    def drawables(self):
        """(node, world matrix) of every node with a mesh."""
        return [(n, m) for n, m in self.root.walk() if n.mesh is not None]

    def lights(self):
        """Lights in world space: (node, Light with world position/direction)."""
        return [(node, node.light.placed(world)) for node, world in self.root.walk() if node.light is not None]

    def cameras(self):
        """(node, world matrix) of every node that carries a camera, depth first."""
        return [(n, m) for n, m in self.root.walk() if n.camera is not None]

    def textures(self):
        """The distinct textures of the drawn materials, in drawing order."""
        found = {}
        for node, _ in self.drawables():
            if node.material is not None:
                found.update((id(t), t) for t in node.material.textures())
        return list(found.values())

    def bounds(self):
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for node, world in self.drawables():
            a, b = node.mesh.bounds(world)
            lo, hi = np.minimum(lo, a), np.maximum(hi, b)
        if not np.all(np.isfinite(lo)):
            return np.zeros(3), np.zeros(3)
        return lo, hi

    def region(self, bounds=None):
        """The cubic voxel region: the file's `voxel_region`, else the bounds (given, or
        computed) padded by 5%."""
        if self.voxel_region is not None:
            return self.voxel_region
        lo, hi = bounds if bounds is not None else self.bounds()
        size = float(np.max(hi - lo)) * 1.05 or 1.0
        return VoxelRegion((lo + hi) / 2.0, size)


def _path_to(root, target):
    """The nodes from `root` down to `target`, both included (None where it is not below)."""
    stack = [(root, (root,))]
    while stack:
        node, path = stack.pop()
        if node is target:
            return list(path)
        stack.extend((child, path + (child,)) for child in node.children)
    return None


# ---- primitive meshes (local frames) -----------------------------------------------------

def quad_mesh(vertices):
    """Two triangles over four vertices; the normal follows the right-hand rule of their order."""
    v = np.asarray(vertices, float)
    n = np.cross(v[1] - v[0], v[2] - v[0]) + np.cross(v[2] - v[0], v[3] - v[0])
    n /= np.linalg.norm(n)
    return Mesh(v, np.tile(n, (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]))


def box_mesh():
    """Unit cube centred at the origin, outward normals, flat faces."""
    positions, normals, indices = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            w = np.cross(n, u)  # u x w = n: counter-clockwise seen from outside
            c = 0.5 * n
            base = len(positions)
            for du, dw in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
                positions.append(c + du * u + dw * w)
                normals.append(n)
            indices += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return Mesh(np.array(positions), np.array(normals), np.array(indices))


def sphere_mesh(segments=48, rings=24):
    """Unit sphere, smooth normals."""
    positions = []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            positions.append((math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)))
    indices = []
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            if i > 0:
                indices.append([a, b, a + 1])
            if i < rings - 1:
                indices.append([a + 1, b, b + 1])
    p = np.array(positions)
    return Mesh(p, p.copy(), np.array(indices))
