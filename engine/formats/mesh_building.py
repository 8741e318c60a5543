"""What the mesh-file readers share (plain Python/numpy, no GL): the default material (a grey
Lambertian, albedo 0.8), the images and textures of one file, each made once, and the geometry
made from a file's vertex data: face, flat and smooth (area-weighted) normals, tangents from
texture coordinates (Lengyel's per-triangle derivatives, summed per vertex), and a checked
surface mesh (vertex data finite and within +-MAX_MAGNITUDE, zero-area triangles and unused
vertices dropped). Used by engine/formats/mesh_files.py (OBJ+MTL, PLY, STL, OFF), engine/formats/gltf/
(glTF) and engine/formats/scene_api.py (meshes built in code).
"""
import hashlib

import numpy as np

from ..core.errors import warn
from ..core.limits import MAX_MAGNITUDE
from ..scene.model import Material, Mesh, Texture


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


def flat_normals(positions, triangles, *attributes):
    """Unshared corners with each triangle's own normal: (positions, normals, triangles,
    attributes...) with every per-vertex array of `attributes` (or None) expanded the same way."""
    corners = triangles.reshape(-1)
    normals = np.repeat(_unit(face_normals(positions, triangles)), 3, axis=0).astype(np.float32)
    expanded = [None if x is None else x[corners] for x in attributes]
    return (positions[corners], normals, np.arange(len(corners), dtype=np.uint32).reshape(-1, 3), *expanded)


def smooth_normals(positions, triangles, *attributes):
    """(positions, normals, triangles, attributes...): each vertex's normal the sum of its
    faces' normals weighted by their areas, unit length; where faces facing apart share a
    vertex and that sum (nearly) cancels, flat normals instead (flat_normals)."""
    faces = face_normals(positions, triangles)
    sums = np.zeros_like(positions, dtype=np.float64)
    np.add.at(sums, triangles.reshape(-1), np.repeat(faces, 3, axis=0))
    lengths = np.linalg.norm(sums[triangles.reshape(-1)], axis=1)
    if not np.all(lengths > 1e-6 * np.repeat(np.linalg.norm(faces, axis=1), 3)):
        return flat_normals(positions, triangles, *attributes)
    return (positions, _unit(sums), triangles, *attributes)


def surface_mesh(positions, triangles, normals=None, texcoords=None):
    """(mesh, dropped): a Mesh of the triangles whose vertex data is finite and within
    +-MAX_MAGNITUDE and whose area is not zero (None if none is left), and how many triangles
    were dropped for their vertex data (zero-area ones are not counted: they draw nothing).
    Its normals: the given ones scaled to unit length where every one of them has a length,
    else smooth_normals."""
    positions = np.asarray(positions, np.float64)
    data = [positions] if texcoords is None else [positions, np.asarray(texcoords, np.float64)]
    valid = np.all([np.all(np.abs(array[triangles]) <= MAX_MAGNITUDE, axis=(1, 2)) for array in data], axis=0)
    triangles = triangles[valid]
    triangles = triangles[np.linalg.norm(face_normals(positions, triangles), axis=1) > 0]
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
        positions, normals, triangles, texcoords = smooth_normals(positions, triangles, texcoords)
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
