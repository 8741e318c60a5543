"""The scene model: nodes, transforms, meshes, materials, lights, camera. Plain Python and
numpy, no GL: the renderer uploads what it needs and reads it again every frame, so an
edit (a moved light, a new albedo) shows on the next frame."""
import math
from dataclasses import dataclass, field

import numpy as np

from . import transforms


@dataclass
class Material:
    name: str
    albedo: np.ndarray = field(default_factory=lambda: np.array([0.8, 0.8, 0.8]))
    roughness: float = 1.0
    metalness: float = 0.0
    specular: float = 0.0  # dielectric reflectance at normal incidence (F0); 0 = Lambertian
    emission: np.ndarray = field(default_factory=lambda: np.zeros(3))  # radiance, front side


@dataclass
class Mesh:
    """Triangles in the node's local frame: positions (V,3), normals (V,3), indices (T,3)."""

    positions: np.ndarray
    normals: np.ndarray
    indices: np.ndarray

    def __post_init__(self):
        # Immutable: the renderer knows a mesh is unchanged when it is the same object. To
        # change geometry, give the node a new Mesh.
        for name in ("positions", "normals", "indices"):
            array = np.array(getattr(self, name))
            array.flags.writeable = False
            setattr(self, name, array)

    def bounds(self, matrix):
        p = transforms.transform_points(matrix, self.positions)
        return p.min(axis=0), p.max(axis=0)


@dataclass
class Light:
    type: str  # point | spot | directional
    intensity: np.ndarray  # point/spot: radiant intensity W/sr; directional: irradiance W/m^2
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    direction: np.ndarray = field(default_factory=lambda: np.array([0.0, -1.0, 0.0]))
    range: float = 0.0  # 0: pure inverse square, no cut-off
    inner_angle_deg: float = 30.0  # spot: full intensity inside
    outer_angle_deg: float = 45.0  # spot: zero outside
    cast_shadows: bool = True


@dataclass
class Camera:
    position: np.ndarray
    look_at: np.ndarray
    up: np.ndarray
    vertical_fov_deg: float
    width: int
    height: int

    def view_matrix(self):
        return transforms.look_at(self.position, self.look_at, self.up)

    def projection_matrix(self, aspect, near, far):
        return transforms.perspective(self.vertical_fov_deg, aspect, near, far)


@dataclass
class Node:
    """A named node of the scene graph with a local transform (T * R * S)."""

    name: str
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation_deg: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: np.ndarray = field(default_factory=lambda: np.ones(3))
    mesh: Mesh = None
    material: Material = None
    light: Light = None
    children: list = field(default_factory=list)

    def local_matrix(self):
        return transforms.compose(self.translation, self.rotation_deg, self.scale)

    def walk(self, parent=np.eye(4)):
        """Yield (node, world_matrix) depth first."""
        world = parent @ self.local_matrix()
        yield self, world
        for child in self.children:
            yield from child.walk(world)

    def find(self, name):
        return next((node for node, _ in self.walk() if node.name == name), None)


@dataclass
class VoxelRegion:
    center: np.ndarray
    size: float


@dataclass
class Scene:
    name: str
    root: Node
    camera: Camera
    materials: dict
    voxel_region: VoxelRegion = None  # None: derived from the geometry's bounds
    source: str = None

    def drawables(self):
        """(node, world matrix) of every node with a mesh."""
        return [(n, m) for n, m in self.root.walk() if n.mesh is not None]

    def lights(self):
        """Lights in world space: (node, Light with world position/direction)."""
        out = []
        for node, world in self.root.walk():
            if node.light is None:
                continue
            light = node.light
            position = transforms.transform_points(world, [light.position])[0]
            direction = world[:3, :3] @ light.direction
            norm = np.linalg.norm(direction)
            out.append((node, Light(light.type, np.asarray(light.intensity, float), position,
                                    direction / norm if norm > 0 else light.direction, light.range,
                                    light.inner_angle_deg, light.outer_angle_deg, light.cast_shadows)))
        return out

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
