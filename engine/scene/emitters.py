"""Emissive surfaces as area lights, read off a frame's draws. GL-free.

Direct light from an emitter is evaluated exactly per triangle with Lambert's polygon formula
(glsl/lib/emitters.glsl), and shadowed by one visibility cone per patch: the triangles of one
draw whose normals share a dominant axis and sign (a quad is one patch, a box six, a sphere six
caps). A triangle's radiance is its material's emission times the mean of the emissive
texture over the triangle (sampled at EMISSION_TEXTURE_SAMPLES points spread over it).
"""
from dataclasses import dataclass

import numpy as np

from ..core import transforms
from ..core.constants import struct_dtype

TRIANGLE_DTYPE = struct_dtype("EmitterTriangle")
PATCH_DTYPE = struct_dtype("EmitterPatch")
EMISSION_TEXTURE_SAMPLES = 4  # per side of the barycentric lattice: 4 * 5 / 2 = 10 samples a triangle


def srgb_to_linear(c):
    """sRGB-encoded values in 0..1 to linear (the sRGB transfer function, IEC 61966-2-1)."""
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


@dataclass(frozen=True, eq=False)
class Emitters:
    """The frame's emissive triangles (TRIANGLE_DTYPE records) and patches (PATCH_DTYPE)."""

    triangles: np.ndarray
    patches: np.ndarray

    @property
    def count(self):
        return len(self.patches)


def is_emissive(material):
    return bool(np.any(np.asarray(material.emission) > 0.0))


def scene_emits(scene):
    """Whether any surface of the scene emits light."""
    return any(is_emissive(node.material) for node, _ in scene.drawables())


def frame_emitters(draws):
    """The Emitters of a frame's emissive draws (changes.FrameInputs.emissive_draws)."""
    triangles, patches = [], []
    for draw in draws:
        corners, radiance = _emissive_triangles(draw)
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        areas = 0.5 * np.linalg.norm(normals, axis=1)
        keep = (areas > 0.0) & np.any(radiance > 0.0, axis=1)
        corners, radiance, normals, areas = corners[keep], radiance[keep], normals[keep], areas[keep]
        axis = np.argmax(np.abs(normals), axis=1)
        facing = 2 * axis + (normals[np.arange(len(normals)), axis] < 0.0)  # +x, -x, +y, ... as the face views
        for face in np.unique(facing):
            chosen = facing == face
            patches.append(_patch(corners[chosen], normals[chosen], areas[chosen], sum(len(t) for t in triangles)))
            records = np.zeros(int(chosen.sum()), TRIANGLE_DTYPE)
            for field, k in (("a", 0), ("b", 1), ("c", 2)):
                records[field][:, :3] = corners[chosen, k]
            records["radiance"][:, :3] = radiance[chosen]
            triangles.append(records)
    return Emitters(np.concatenate(triangles) if triangles else np.zeros(0, TRIANGLE_DTYPE),
                    np.array(patches, PATCH_DTYPE) if patches else np.zeros(0, PATCH_DTYPE))


def _emissive_triangles(draw):
    """World-space corners (T, 3, 3) and radiance (T, 3) of a draw's triangles."""
    mesh, material = draw.mesh, draw.material
    positions = transforms.transform_points(draw.world, mesh.positions)
    indices = np.asarray(mesh.indices).reshape(-1, 3)
    corners = positions[indices]
    radiance = np.tile(np.asarray(material.emission, np.float64), (len(indices), 1))
    if material.emissive_texture is not None and mesh.texcoords is not None:
        radiance *= _texture_means(material.emissive_texture, np.asarray(mesh.texcoords, np.float64)[indices])
    return corners, radiance


def _texture_means(texture, uv):
    """Mean linear RGB of a texture over each triangle of texture coordinates uv (T, 3, 2),
    from a barycentric lattice of samples inside it (nearest texel, with the texture's wrap)."""
    k = EMISSION_TEXTURE_SAMPLES
    weights = np.array([(i + 1 / 3, j + 1 / 3, k - i - j - 2 / 3) for i in range(k) for j in range(k - i)]) / k
    points = np.einsum("sc,tcd->tsd", weights, uv)  # (T, samples, 2)
    image = texture.image
    height, width = image.shape[:2]
    columns = _wrap(np.floor(points[..., 0] * width).astype(np.int64), width, texture.wrap_s)
    rows = _wrap(np.floor(points[..., 1] * height).astype(np.int64), height, texture.wrap_t)
    texels = image[rows, columns].astype(np.float64) / 255.0
    if texels.ndim == 2:  # grey
        texels = texels[..., None]
    rgb = texels[..., :3] if texels.shape[-1] >= 3 else np.repeat(texels[..., :1], 3, axis=-1)
    if texture.srgb:
        rgb = srgb_to_linear(rgb)
    return rgb.mean(axis=1)


def _wrap(index, size, mode):
    if mode == "CLAMP_TO_EDGE":
        return np.clip(index, 0, size - 1)
    if mode == "MIRRORED_REPEAT":
        period = np.mod(index, 2 * size)
        return np.where(period < size, period, 2 * size - 1 - period)
    return np.mod(index, size)


def _patch(corners, normals, areas, first):
    """A PATCH_DTYPE record for triangles that face about one way."""
    centroids = corners.mean(axis=1)
    centre = (centroids * areas[:, None]).sum(axis=0) / areas.sum()
    radius = float(np.max(np.linalg.norm(corners - centre, axis=2)))
    mean_normal = normals.sum(axis=0)  # area-weighted
    normal = mean_normal / np.linalg.norm(mean_normal)  # facing one way, so never zero
    depth = float(np.max(np.abs((corners - centre) @ normal)))
    record = np.zeros((), PATCH_DTYPE)
    record["sphere"] = (*centre, radius)
    record["plane"] = (*normal, depth)
    record["triangles"][:2] = (first, len(corners))
    return record
