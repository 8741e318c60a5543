"""GPU copies of the scene: vertex and index buffers per mesh and textures per image (each
uploaded once, again when the scene gives it new data, and released when it leaves the
scene), vertex arrays per program, and the per-draw uniforms and texture bindings of the
materials (`bind_material`), which every pass that rasterizes the scene shares.

A large mesh is uploaded with its triangles sorted into spatial clusters, each a range of its
index buffer with its own bounds, so a draw skips the clusters outside a view frustum or a box
(a cube face of a point light's shadow sees about a sixth of a room; a partial voxel update
touches a few cells)."""
import ctypes
import ctypes.util
import math

import numpy as np

from . import transforms
from .emitters import frame_emitters
from .errors import VctError
from .gl_bindings import bind_storage, bind_texture
from .scene import IDENTITY_UV

# Vertex attributes in buffer order, with their float counts. Meshes without texture
# coordinates or tangents get zeros there, without vertex colours white.
VERTEX_ATTRIBUTES = (("in_position", 3), ("in_normal", 3), ("in_texcoord", 2), ("in_tangent", 4), ("in_color", 3),
                     ("in_texcoord1", 2))
# Material texture -> (texture unit, the value it stands for when the material has none), in the
# order of the shaders' per-map arrays (SHADER_ENUMS["MAP"]: uv_transforms, uv_sets).
MATERIAL_TEXTURES = {
    "base_color_texture": ("BASE_COLOR_MAP", (255, 255, 255, 255)),
    "metallic_roughness_texture": ("METAL_ROUGH_MAP", (255, 255, 255, 255)),
    "emissive_texture": ("EMISSIVE_MAP", (255, 255, 255, 255)),
    "normal_texture": ("NORMAL_MAP", (128, 128, 255, 255)),
}
CLUSTER_TRIANGLES = 1024  # meshes are split into clusters of about this many triangles
GL_TEXTURE_WRAP = {"s": 0x2802, "t": 0x2803}
GL_MIRRORED_REPEAT = 0x8370
GL_SRGB8_ALPHA8 = 0x8C43
GL_RGBA8 = 0x8058


class SceneTextures:
    """One GL texture per scene Texture (RGBA8, sRGB-decoded where the image is colour),
    mipmapped and sampled trilinearly. Not anisotropically: on llvmpipe anisotropic filtering
    doubles the G-buffer's cost on Sponza, and it filters the voxelizer's stretched voxel
    footprints with so many samples that a voxelization of Sponza takes minutes instead of a
    second (even at an explicit level of detail)."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.textures = {}  # id(Texture) -> (Texture, GL texture)
        self.defaults = {name: self._upload(np.array([[value]], dtype="u1"), False, "REPEAT", "REPEAT")
                         for name, (_, value) in MATERIAL_TEXTURES.items()}

    def get(self, texture):
        entry = self.textures.get(id(texture))
        if entry is None or entry[0] is not texture:
            limit = self.ctx.info["GL_MAX_TEXTURE_SIZE"]
            height, width = texture.image.shape[:2]
            if max(width, height) > limit:
                raise VctError(f"{width}x{height} exceeds the driver's texture limit of {limit}", source=texture.name)
            entry = (texture, self._upload(texture.image, texture.srgb, texture.wrap_s, texture.wrap_t))
            self.textures[id(texture)] = entry
        return entry[1]

    def _upload(self, image, srgb, wrap_s, wrap_t):
        rgba = _rgba(image)
        gl_texture = self.ctx.texture((rgba.shape[1], rgba.shape[0]), 4, rgba.tobytes(),
                                      internal_format=GL_SRGB8_ALPHA8 if srgb else GL_RGBA8)
        gl_texture.build_mipmaps()
        gl_texture.repeat_x, gl_texture.repeat_y = wrap_s != "CLAMP_TO_EDGE", wrap_t != "CLAMP_TO_EDGE"
        for axis, wrap in (("s", wrap_s), ("t", wrap_t)):
            if wrap == "MIRRORED_REPEAT":  # moderngl has no setting for it
                _gl_texture_parameter(gl_texture.glo, GL_TEXTURE_WRAP[axis], GL_MIRRORED_REPEAT)
        return gl_texture

    def retain(self, textures):
        live = {id(t) for t in textures}
        for key in [k for k in self.textures if k not in live]:
            self.textures.pop(key)[1].release()

    def memory_bytes(self):
        """GPU bytes of the scene's textures: RGBA8 with a mip chain (x 4/3)."""
        return int(sum(t.width * t.height * 4 * 4 / 3 for _, t in self.textures.values()))

    def release(self):
        for _, gl_texture in self.textures.values():
            gl_texture.release()
        for gl_texture in self.defaults.values():
            gl_texture.release()
        self.textures.clear()


class MeshClusters:
    """The clusters of a mesh: triangles binned by centroid into a grid of cells over the
    mesh's bounds, each cell's triangles a contiguous range of the sorted index buffer."""

    def __init__(self, positions, triangles):
        count = len(triangles)
        cells = max(1, min(16, round((count / CLUSTER_TRIANGLES) ** (1 / 3))))
        centroids = positions[triangles].mean(axis=1)
        lo, hi = positions.min(axis=0), positions.max(axis=0)
        cell = np.clip(((centroids - lo) / np.maximum(hi - lo, 1e-30) * cells).astype(np.int64), 0, cells - 1)
        keys = (cell[:, 0] * cells + cell[:, 1]) * cells + cell[:, 2]
        order = np.argsort(keys, kind="stable")
        self.triangles = triangles[order]
        starts = np.flatnonzero(np.r_[True, np.diff(keys[order]) != 0])
        self.first = starts * 3                                    # first index of each cluster
        self.count = np.diff(np.r_[starts, count]) * 3              # indices in each cluster
        corners = positions[self.triangles]
        self.lo = np.minimum.reduceat(corners.min(axis=1), starts)  # local bounds of each cluster
        self.hi = np.maximum.reduceat(corners.max(axis=1), starts)

    def ranges(self, world, view_projection=None, box=None):
        """(first, count) index ranges of the clusters inside a view frustum and/or a world box
        (all without either), adjacent ones merged. A mesh of one cluster is not tested against a
        frustum alone: its few triangles cost the clipper less than the test costs Python (a point
        light's six cube faces test every draw)."""
        if len(self.first) == 1 and box is None:
            return [(int(self.first[0]), int(self.count[0]))]
        keep = np.ones(len(self.first), bool)
        if view_projection is not None or box is not None:
            world_corners = transforms.box_corners(self.lo, self.hi) @ world[:3, :3].T + world[:3, 3]  # (clusters, 8, 3)
            if box is not None:
                keep &= np.all(world_corners.min(axis=1) <= box[1], axis=1) & np.all(world_corners.max(axis=1) >= box[0], axis=1)
            if view_projection is not None:
                keep &= ~transforms.outside_frustum(world_corners, view_projection)
        ranges = []
        for first, count in zip(self.first[keep], self.count[keep]):
            if ranges and ranges[-1][0] + ranges[-1][1] == first:
                ranges[-1] = (ranges[-1][0], ranges[-1][1] + count)
            else:
                ranges.append((int(first), int(count)))
        return ranges


class SceneGeometry:
    def __init__(self, ctx):
        self.ctx = ctx
        self.buffers = {}  # id(mesh) -> (the mesh's arrays, vbo, ibo, clusters)
        self.vertex_arrays = {}  # handle -> (program, {id(mesh): vao})
        self.textures = SceneTextures(ctx)
        self.draw_calls = 0

    def _buffers(self, mesh):
        """The mesh's buffers, uploaded again when it holds new arrays."""
        entry = self.buffers.get(id(mesh))
        if entry is not None and not all(a is b for a, b in zip(entry[0], mesh.arrays())):
            self._release_mesh(id(mesh))
            entry = None
        if entry is None:
            count = len(mesh.positions)
            columns = [mesh.positions, mesh.normals,
                       mesh.texcoords if mesh.texcoords is not None else np.zeros((count, 2)),
                       mesh.tangents if mesh.tangents is not None else np.zeros((count, 4)),
                       mesh.colors if mesh.colors is not None else np.ones((count, 3)),
                       mesh.texcoords1 if mesh.texcoords1 is not None else np.zeros((count, 2))]
            data = np.hstack([np.asarray(c, dtype="f4") for c in columns])
            clusters = MeshClusters(np.asarray(mesh.positions, np.float64), np.asarray(mesh.indices, np.int64).reshape(-1, 3))
            entry = (mesh.arrays(), self.ctx.buffer(data.tobytes()), self.ctx.buffer(clusters.triangles.astype("i4").tobytes()),
                     clusters)
            self.buffers[id(mesh)] = entry
        return entry

    def vertex_array(self, handle, mesh):
        program, arrays = self.vertex_arrays.get(handle, (None, {}))
        if program is not handle.program:
            for vao in arrays.values():
                vao.release()
            program, arrays = handle.program, {}
            self.vertex_arrays[handle] = (program, arrays)
        _, vbo, ibo, _ = self._buffers(mesh)  # uploaded again, without vertex arrays, if the mesh has new arrays
        vao = arrays.get(id(mesh))
        if vao is None:
            # The attributes the compiler kept, and padding for the others.
            layout = " ".join(f"{size}f" if name in program else f"{4 * size}x" for name, size in VERTEX_ATTRIBUTES)
            names = [name for name, _ in VERTEX_ATTRIBUTES if name in program]
            vao = self.ctx.vertex_array(program, [(vbo, layout, *names)], index_buffer=ibo)
            arrays[id(mesh)] = vao
        return vao

    def bind_material(self, handle, material):
        """Set a program's material uniforms and bind the material's textures (white, or a
        flat normal, where it has none)."""
        handle.set(albedo=tuple(material.albedo), alpha=float(material.alpha), roughness=float(material.roughness),
                   metalness=float(material.metalness), dielectric_f0=float(material.specular),
                   emission=tuple(material.emission), normal_scale=float(material.normal_scale),
                   alpha_cutoff=float(material.alpha_cutoff) if material.alpha_tested else -1.0,
                   uv_transforms=b"".join(_uv_matrix(material.uv_transform(name)) for name in MATERIAL_TEXTURES),
                   uv_sets=tuple(int(material.uv_sets.get(name, 0)) for name in MATERIAL_TEXTURES))
        for field, (unit, _) in MATERIAL_TEXTURES.items():
            texture = getattr(material, field)
            gl_texture = self.textures.get(texture) if texture is not None else self.textures.defaults[field]
            bind_texture(gl_texture, unit)

    def draw(self, handle, draws, materials=False, cull_single_sided=False, view_projection=None, box=None):
        """Draw each of `draws` (changes.Draw) with `handle`, with its material bound if asked,
        skipping the clusters outside `view_projection`'s frustum and the world `box` (lo, hi).
        `cull_single_sided`: back faces of single-sided materials are not drawn."""
        for draw in draws:
            vao = self.vertex_array(handle, draw.mesh)
            ranges = self.buffers[id(draw.mesh)][3].ranges(draw.world, view_projection, box)
            if not ranges:
                continue
            handle.set(model=transforms.gl_bytes(draw.world),
                       normal_matrix=np.asarray(transforms.normal_matrix(draw.world), "f4").T.tobytes())
            if materials:
                self.bind_material(handle, draw.material)
            cull = cull_single_sided and not draw.material.double_sided
            if cull:  # a mirroring transform turns the front faces clockwise
                self.ctx.front_face = "cw" if np.linalg.det(draw.world[:3, :3]) < 0 else "ccw"
                self.ctx.enable(self.ctx.CULL_FACE)
            for first, count in ranges:
                vao.render(self.ctx.TRIANGLES, vertices=count, first=first)
                self.draw_calls += 1
            if cull:
                self.ctx.disable(self.ctx.CULL_FACE)
                self.ctx.front_face = "ccw"

    def retain(self, draws):
        """Release the buffers, vertex arrays and textures of meshes and images that no draw
        uses any more."""
        live = {id(d.mesh) for d in draws}
        for key in [k for k in self.buffers if k not in live]:
            self._release_mesh(key)
        self.textures.retain({t for d in draws for t in d.material.textures()})

    def _release_mesh(self, key):
        for _, arrays in self.vertex_arrays.values():
            vao = arrays.pop(key, None)
            if vao is not None:
                vao.release()
        _, vbo, ibo, _ = self.buffers.pop(key)
        vbo.release()
        ibo.release()

    def release(self):
        for key in list(self.buffers):  # every vertex array belongs to an uploaded mesh
            self._release_mesh(key)
        self.vertex_arrays.clear()
        self.textures.release()


class EnvironmentMap:
    """The scene's environment (engine.scene.Environment) as one RGBA32F texture with its mip
    chain, repeating in u and clamped in v (glsl/lib/environment.glsl): the map, or one texel
    of a uniform sky's radiance; uploaded when the environment changes."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.texture = None
        self.environment = None
        self.upload(None)

    def upload(self, environment):
        """Hold `environment` (None: none)."""
        if self.texture is not None:
            self.texture.release()
        self.environment = environment
        if environment is not None and environment.image is not None:
            height, width = environment.image.shape[:2]
            limit = self.ctx.info["GL_MAX_TEXTURE_SIZE"]
            if max(width, height) > limit:
                raise VctError(f"{width}x{height} exceeds the driver's texture limit of {limit}", source=environment.name)
            rgb = environment.image
        else:
            rgb = np.zeros((1, 1, 3)) if environment is None else np.asarray(environment.radiance).reshape(1, 1, 3)
        rgba = np.concatenate([rgb, np.ones(rgb.shape[:2] + (1,))], axis=2).astype("f4")
        self.texture = self.ctx.texture((rgba.shape[1], rgba.shape[0]), 4, np.ascontiguousarray(rgba).tobytes(), dtype="f4")
        self.texture.build_mipmaps()
        self.texture.filter = (self.ctx.LINEAR_MIPMAP_LINEAR, self.ctx.LINEAR)
        self.texture.repeat_x, self.texture.repeat_y = True, False

    def bind(self, handle):
        """Bind the map and set the uniforms of glsl/lib/environment.glsl."""
        environment = self.environment
        bind_texture(self.texture, "ENVIRONMENT")
        rotation = environment.rotation() if environment is not None else np.eye(3)
        handle.set(environment_present=environment is not None,
                   environment_scale=float(environment.scale) if environment is not None else 0.0,
                   environment_rotation=tuple(np.asarray(rotation, "f4").T.reshape(-1)),
                   environment_texel_angle=2.0 * math.pi / self.texture.width)

    def release(self):
        if self.texture is not None:
            self.texture.release()
            self.texture = None


class EmitterBuffers:
    """The frame's emitters (engine/emitters.py) in storage buffers, for the passes that light
    surfaces with them."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.triangles = self.patches = None
        self.count = 0
        self.upload(frame_emitters([]))

    def upload(self, emitters):
        self.release()
        # An empty storage buffer cannot be made: hold one zero record.
        self.triangles = self.ctx.buffer(emitters.triangles.tobytes() or bytes(emitters.triangles.dtype.itemsize))
        self.patches = self.ctx.buffer(emitters.patches.tobytes() or bytes(emitters.patches.dtype.itemsize))
        self.count = emitters.count

    def bind(self, handle):
        bind_storage(self.triangles, "EMITTER_TRIANGLES")
        bind_storage(self.patches, "EMITTER_PATCHES")
        handle.set(emitter_patch_count=self.count)

    def release(self):
        for buffer in (self.triangles, self.patches):
            if buffer is not None:
                buffer.release()
        self.triangles = self.patches = None


def vertex_extras(draw):
    """Whether a draw's mesh has vertex colours or a second texture coordinate set, or its
    material reads set 1 or transforms its texture coordinates: the programs that pass them on
    and transform them (VERTEX_EXTRAS) draw it."""
    mesh, material = draw.mesh, draw.material
    return (mesh.colors is not None or mesh.texcoords1 is not None or any(material.uv_sets.values())
            or any(transform != IDENTITY_UV for transform in material.uv_transforms.values()))


def _uv_matrix(rows):
    """A 2x3 texture coordinate transform as the bytes of a GLSL mat3 (column-major)."""
    (a, b, c), (d, e, f) = rows
    return np.array([a, d, 0.0, b, e, 0.0, c, f, 1.0], "f4").tobytes()


def _rgba(image):
    """uint8 (H, W, C) with C in 1..4 -> (H, W, 4): grey to RGB, opaque where it has no alpha."""
    if image.ndim == 2:
        image = image[..., None]
    channels = image.shape[2]
    rgb = np.repeat(image[..., :1], 3, axis=2) if channels <= 2 else image[..., :3]
    alpha = image[..., -1:] if channels in (2, 4) else np.full(image.shape[:2] + (1,), 255, np.uint8)
    return np.ascontiguousarray(np.concatenate([rgb, alpha], axis=2))


def _gl_texture_parameter(texture, parameter, value):
    """glTextureParameteri (a setting moderngl lacks)."""
    gl = ctypes.CDLL(ctypes.util.find_library("GL") or "libGL.so.1")
    gl.glTextureParameteri(ctypes.c_uint(texture), ctypes.c_uint(parameter), ctypes.c_int(value))

