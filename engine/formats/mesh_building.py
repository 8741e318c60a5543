"""What the mesh-file readers share (plain Python/numpy, no GL): the default material (a grey
Lambertian, albedo 0.8), the images and textures of one file, each made once, and the geometry
made from a file's vertex data: polygons as triangles (ear clipping in the polygon's plane, so
concave ones come out right), face, flat and smooth (angle-weighted) normals, the normals of a
mesh that has none (smooth across edges where faces meet at less than CREASE_DEG, sharp at
sharper ones: one rule for every format and for meshes from trimesh), tangents from texture
coordinates (Lengyel's per-triangle derivatives, summed per vertex), and a checked surface mesh
(vertex data finite and within +-MAX_MAGNITUDE, zero-area triangles and unused vertices
dropped). Used by engine/formats/mesh_files.py (OBJ+MTL, PLY, STL, OFF), engine/formats/gltf/
(glTF) and engine/formats/scene_api.py (meshes built in code).
"""
import hashlib

import numpy as np

from ..core.errors import warn
from ..core.limits import MAX_MAGNITUDE
from ..scene.model import Material, Mesh, Texture


CREASE_DEG = 20.0  # trimesh.graph.smooth_shade's default angle


def default_material():
    return Material(name="default")


# ---- images ------------------------------------------------------------------------------------

class FileTextures:
    """The images and textures of one file, each made once: `pixels` are keyed by what they were
    made from (e.g. the digest of the encoded image), textures by their pixels, colour space and
    wrap modes, so materials that use an image the same way share one Texture."""

    def __init__(self, inputs):
        self.inputs = inputs
        self.images = {}
        self.textures = {}

    def decoded(self, data):
        """(key, pixels) of an encoded image, decoding it on first use."""
        key = hashlib.sha256(data).digest()
        return key, self.pixels(key, lambda: self.inputs.decode_image(data))

    def pixels(self, key, make):
        if key not in self.images:
            self.images[key] = make()
        return self.images[key]

    def texture(self, key, name, srgb, wrap_s, wrap_t):
        texture_key = (key, srgb, wrap_s, wrap_t)
        if texture_key not in self.textures:
            self.textures[texture_key] = Texture(name, self.images[key], srgb, wrap_s, wrap_t)
        return self.textures[texture_key]


# ---- geometry helpers ----------------------------------------------------------------------

def _unit(v):
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def face_normals(positions, triangles):
    """Each triangle's (b - a) x (c - a), in float64: its length is twice the area."""
    corners = np.asarray(positions, np.float64)[triangles]
    return np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])


def with_area(positions, triangles, chunk=2 ** 20):
    """The triangles whose area is not zero (the others draw nothing and have no normal),
    computed a chunk at a time so that the work takes a bounded amount of memory."""
    keep = np.empty(len(triangles), bool)
    for first in range(0, len(triangles), chunk):
        part = triangles[first:first + chunk]
        keep[first:first + chunk] = np.any(face_normals(positions, part) != 0, axis=1)
    return triangles[keep]


def newell_normals(polygons):
    """The Newell normal of each polygon (m, k, 3): twice its vector area, whatever its shape."""
    following = np.roll(polygons, -1, axis=1)
    return np.cross(polygons, following).sum(axis=1)


def quad_triangles(quads):
    """Two triangles (m, 2, 3) of local corner indices per quad (m, 4, 3): split along 0-2
    unless a triangle of that split faces against the quad (a concave quad, whose reflex corner
    is 1 or 3), then along 1-3."""
    normals = newell_normals(quads)
    def facing(a, b, c):
        return np.einsum("ij,ij->i", np.cross(quads[:, b] - quads[:, a], quads[:, c] - quads[:, a]), normals) > 0
    along_02 = facing(0, 1, 2) & facing(0, 2, 3)
    return np.where(along_02[:, None, None], [[0, 1, 2], [0, 2, 3]], [[0, 1, 3], [1, 2, 3]])


def polygon_triangles(points):
    """Triangles (k - 2, 3) of local corner indices covering a simple polygon (k, 3) in its
    order, by ear clipping in the plane of its Newell normal; a fan where it has no area."""
    k = len(points)
    normal = newell_normals(points[None])[0]
    axis = int(np.argmax(np.abs(normal)))
    if not np.any(normal):
        return np.array([[0, i, i + 1] for i in range(1, k - 1)])
    u, v = [(1, 2), (2, 0), (0, 1)][axis]  # the plane across the dominant axis, counter-clockwise about it
    flat = points[:, [u, v]] * [1.0, 1.0 if normal[axis] > 0 else -1.0]

    def cross(o, a, b):
        return (flat[a, 0] - flat[o, 0]) * (flat[b, 1] - flat[o, 1]) - (flat[a, 1] - flat[o, 1]) * (flat[b, 0] - flat[o, 0])

    left, triangles = list(range(k)), []
    while len(left) > 3:
        for at in range(len(left)):
            a, b, c = left[at - 1], left[at], left[(at + 1) % len(left)]
            convex = cross(a, b, c) > 0
            if convex and not any(cross(a, b, p) >= 0 and cross(b, c, p) >= 0 and cross(c, a, p) >= 0
                                  for p in left if p not in (a, b, c)):
                break
        else:  # no ear (a self-crossing or degenerate polygon): cut the first corner
            at = 1
            a, b, c = left[0], left[1], left[2]
        triangles.append((a, b, c))
        del left[at]
    triangles.append(tuple(left))
    return np.array(triangles)


def flat_normals(positions, triangles, *attributes):
    """Unshared corners with each triangle's own normal: (positions, normals, triangles,
    attributes...) with every per-vertex array of `attributes` (or None) expanded the same way."""
    corners = triangles.reshape(-1)
    normals = np.repeat(_unit(face_normals(positions, triangles)), 3, axis=0).astype(np.float32)
    expanded = [None if x is None else x[corners] for x in attributes]
    return (positions[corners], normals, np.arange(len(corners), dtype=np.uint32).reshape(-1, 3), *expanded)


def smooth_normals(positions, triangles, *attributes):
    """(positions, normals, triangles, attributes...): each vertex's normal the sum of its
    faces' unit normals weighted by the face's angle at the vertex (Thuermer and Wuethrich:
    independent of how the faces are cut into triangles), unit length; where faces facing
    apart share a vertex and that sum (nearly) cancels, flat normals instead (flat_normals)."""
    faces = face_normals(positions, triangles)
    corners = np.asarray(positions, np.float64)[triangles]
    angles = np.empty((len(triangles), 3))
    for corner in range(3):
        a = corners[:, (corner + 1) % 3] - corners[:, corner]
        b = corners[:, (corner + 2) % 3] - corners[:, corner]
        angles[:, corner] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    sums = np.zeros_like(positions, dtype=np.float64)
    np.add.at(sums, triangles.reshape(-1), (_unit(faces)[:, None, :] * angles[:, :, None]).reshape(-1, 3))
    lengths = np.linalg.norm(sums[triangles.reshape(-1)], axis=1)
    if not np.all(lengths > 1e-6 * np.repeat(angles.max(axis=1), 3)):
        return flat_normals(positions, triangles, *attributes)
    return (positions, _unit(sums), triangles, *attributes)


def crease_split(positions, triangles):
    """(the source vertex of each new vertex, triangles over the new vertices): the vertices
    split between the groups of faces that meet along edges at less than CREASE_DEG, so that
    normals computed over shared vertices are smooth within a group and sharp between groups
    (trimesh's smooth_shaded splits the same way)."""
    import trimesh

    mesh = trimesh.Trimesh(positions, triangles, process=False, validate=False)
    smooth_edges = mesh.face_adjacency[mesh.face_adjacency_angles < np.radians(CREASE_DEG)]
    groups = trimesh.graph.connected_component_labels(smooth_edges, node_count=len(triangles))
    group_count = int(groups.max()) + 1
    corners = np.asarray(triangles, np.int64).reshape(-1) * group_count + np.repeat(groups, 3)  # (vertex, group)
    split, split_triangles = np.unique(corners, return_inverse=True)
    return split // group_count, split_triangles.reshape(-1, 3)


def crease_normals(positions, triangles, *attributes):
    """(positions, normals, triangles, attributes...) of a mesh given without normals: its
    vertices split at edges sharper than CREASE_DEG (crease_split), then smooth_normals."""
    source, triangles = crease_split(positions, triangles)
    return smooth_normals(positions[source], triangles, *(None if a is None else a[source] for a in attributes))


def surface_mesh(positions, triangles, normals=None, texcoords=None):
    """(mesh, dropped): a Mesh of the triangles whose vertex data is finite and within
    +-MAX_MAGNITUDE and whose area is not zero (None if none is left), and how many triangles
    were dropped for their vertex data (zero-area ones are not counted: they draw nothing).
    Its normals: the given ones scaled to unit length where every one of them has a length,
    else crease_normals."""
    positions = np.asarray(positions, np.float64)
    data = [positions] if texcoords is None else [positions, np.asarray(texcoords, np.float64)]
    valid = np.all([np.all(np.abs(array[triangles]) <= MAX_MAGNITUDE, axis=(1, 2)) for array in data], axis=0)
    triangles = triangles[valid]
    triangles = with_area(positions, triangles)
    dropped = int(np.count_nonzero(~valid))
    if len(triangles) == 0:
        return None, dropped
    used, triangles = np.unique(triangles, return_inverse=True)  # drop the vertices no triangle uses
    triangles = triangles.reshape(-1, 3)
    positions = positions[used]
    texcoords = None if texcoords is None else np.asarray(texcoords, np.float32)[used]
    if normals is not None:
        normals = np.asarray(normals, np.float64)[used]
        lengths = np.linalg.norm(np.where(np.isfinite(normals), normals, 0.0), axis=1)
        normals = normals / lengths[:, None] if np.all(np.isfinite(normals)) and np.all(lengths > 1e-6) else None
    if normals is None:
        positions, normals, triangles, texcoords = crease_normals(positions, triangles, texcoords)
    return Mesh(positions.astype(np.float32), normals.astype(np.float32), triangles.astype(np.uint32), texcoords), dropped


def warn_dropped(name, dropped):
    """One warning per mesh file for the triangles surface_mesh dropped for their vertex data."""
    if dropped:
        warn(f"{dropped} triangle{'s' if dropped > 1 else ''} dropped: vertex positions or texture coordinates "
             f"that are not finite or lie beyond +-{MAX_MAGNITUDE:g}", source=name)


def generate_tangents(positions, normals, texcoords, triangles):
    """Tangents (V,4) from texture coordinates (glTF convention, v downwards): each triangle's
    dP/du and dP/dv (Lengyel's method) summed at its corners, the tangent dP/du made orthogonal to
    the normal, w = +1 where cross(normal, tangent) points towards the image's top (-dP/dv), else
    -1. Where the texture coordinates give no direction, any tangent orthogonal to the normal."""
    p = positions[triangles].astype(np.float64)
    uv = texcoords[triangles].astype(np.float64)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    r = np.divide(1.0, det, out=np.zeros_like(det), where=np.abs(det) > 1e-20)[:, None]
    du = (e1 * d2[:, 1:] - e2 * d1[:, 1:]) * r
    dv = (e2 * d1[:, :1] - e1 * d2[:, :1]) * r
    tangent_sum = np.zeros((len(positions), 3))
    v_sum = np.zeros((len(positions), 3))
    for corner in range(3):
        np.add.at(tangent_sum, triangles[:, corner], du)
        np.add.at(v_sum, triangles[:, corner], dv)
    n = _unit(normals.astype(np.float64))
    t = _unit(tangent_sum - n * np.sum(n * tangent_sum, axis=1, keepdims=True))
    missing = ~t.any(axis=1)
    if missing.any():  # any direction orthogonal to the normal
        m = n[missing]
        helper = np.where(np.abs(m[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        t[missing] = _unit(np.cross(helper, m))
    w = np.where(np.sum(np.cross(n, t) * -v_sum, axis=1) < 0, -1.0, 1.0)
    return np.hstack([t, w[:, None]]).astype(np.float32)
