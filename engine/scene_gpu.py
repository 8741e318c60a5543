"""GPU copies of the scene: vertex and index buffers per mesh and textures per image (each
uploaded once, again when the scene gives it new data, and released when it leaves the
scene), vertex arrays per program, and the per-draw uniforms and texture bindings of the
materials (`bind_material`), which every pass that rasterizes the scene shares."""
import ctypes
import ctypes.util

import numpy as np

from . import transforms
from .constants import TEXTURE_UNIT
from .errors import VctError

# Vertex attributes in buffer order, with their float counts. Meshes without texture
# coordinates or tangents get zeros.
VERTEX_ATTRIBUTES = (("in_position", 3), ("in_normal", 3), ("in_texcoord", 2), ("in_tangent", 4))
# Material texture -> (texture unit, the value it stands for when the material has none).
MATERIAL_TEXTURES = {
    "base_color_texture": ("BASE_COLOR_MAP", (255, 255, 255, 255)),
    "metallic_roughness_texture": ("METAL_ROUGH_MAP", (255, 255, 255, 255)),
    "emissive_texture": ("EMISSIVE_MAP", (255, 255, 255, 255)),
    "normal_texture": ("NORMAL_MAP", (128, 128, 255, 255)),
}
ALPHA_TESTED = ("MASK", "BLEND")  # BLEND is drawn as a cut-out (engine.scene.Material)
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


class SceneGeometry:
    def __init__(self, ctx):
        self.ctx = ctx
        self.buffers = {}  # id(mesh) -> (the mesh's arrays, vbo, ibo)
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
                       mesh.tangents if mesh.tangents is not None else np.zeros((count, 4))]
            data = np.hstack([np.asarray(c, dtype="f4") for c in columns])
            entry = (mesh.arrays(), self.ctx.buffer(data.tobytes()), self.ctx.buffer(mesh.indices.astype("i4").tobytes()))
            self.buffers[id(mesh)] = entry
        return entry

    def vertex_array(self, handle, mesh):
        program, arrays = self.vertex_arrays.get(handle, (None, {}))
        if program is not handle.program:
            for vao in arrays.values():
                vao.release()
            program, arrays = handle.program, {}
            self.vertex_arrays[handle] = (program, arrays)
        _, vbo, ibo = self._buffers(mesh)  # uploaded again, without vertex arrays, if the mesh has new arrays
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
                   has_normal_map=material.normal_texture is not None,
                   alpha_cutoff=float(material.alpha_cutoff) if material.alpha_mode in ALPHA_TESTED else -1.0)
        for field, (unit, _) in MATERIAL_TEXTURES.items():
            texture = getattr(material, field)
            gl_texture = self.textures.get(texture) if texture is not None else self.textures.defaults[field]
            gl_texture.use(TEXTURE_UNIT[unit])

    def draw(self, handle, draws, materials=False, cull_single_sided=False):
        """Draw each of `draws` (changes.Draw) with `handle`, with its material bound if asked.
        `cull_single_sided`: back faces of single-sided materials are not drawn."""
        for draw in draws:
            handle.set(model=transforms.gl_bytes(draw.world),
                       normal_matrix=np.asarray(transforms.normal_matrix(draw.world), "f4").T.tobytes())
            if materials:
                self.bind_material(handle, draw.material)
            cull = cull_single_sided and not draw.material.double_sided
            if cull:  # a mirroring transform turns the front faces clockwise
                self.ctx.front_face = "cw" if np.linalg.det(draw.world[:3, :3]) < 0 else "ccw"
                self.ctx.enable(self.ctx.CULL_FACE)
            self.vertex_array(handle, draw.mesh).render(self.ctx.TRIANGLES)
            if cull:
                self.ctx.disable(self.ctx.CULL_FACE)
                self.ctx.front_face = "ccw"
            self.draw_calls += 1

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
        _, vbo, ibo = self.buffers.pop(key)
        vbo.release()
        ibo.release()

    def release(self):
        for _, arrays in self.vertex_arrays.values():
            for vao in arrays.values():
                vao.release()
        for _, vbo, ibo in self.buffers.values():
            vbo.release()
            ibo.release()
        self.vertex_arrays.clear()
        self.buffers.clear()
        self.textures.release()


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

