"""G-buffer pass: rasterizes the scene from the camera into position, normal, material and
emission targets (float), with a depth buffer."""
from .. import transforms
from ..constants import HDR_FORMAT, TEXTURE_UNIT


class GBufferPass:
    TARGETS = ("GBUF_POSITION", "GBUF_NORMAL", "GBUF_ALBEDO", "GBUF_EMISSION")

    def __init__(self, ctx, programs, geometry, size):
        self.ctx = ctx
        self.geometry = geometry
        self.program = programs.program(vertex_shader="gbuffer.vert", fragment_shader="gbuffer.frag")
        self.textures = []
        self.depth = None
        self.framebuffer = None
        self.resize(size)

    def resize(self, size):
        self._release_targets()
        self.size = size
        self.textures = [self.ctx.texture(size, 4, dtype=HDR_FORMAT if name == "GBUF_POSITION" else "f2")
                         for name in self.TARGETS]
        for texture in self.textures:
            texture.filter = (self.ctx.NEAREST, self.ctx.NEAREST)
        self.depth = self.ctx.depth_texture(size)
        self.framebuffer = self.ctx.framebuffer(color_attachments=self.textures, depth_attachment=self.depth)

    def render(self, scene, view_projection):
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, *self.size)
        self.framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable_only(self.ctx.DEPTH_TEST)
        self.program.set(view_projection=transforms.gl_bytes(view_projection))

        def material(node, world):
            m = node.material
            self.program.set(albedo=tuple(m.albedo), roughness=m.roughness, metalness=m.metalness,
                             dielectric_f0=m.specular, emission=tuple(m.emission))

        self.geometry.draw(self.program, scene, material)

    def bind(self):
        for name, texture in zip(self.TARGETS, self.textures):
            texture.use(TEXTURE_UNIT[name])

    def _release_targets(self):
        for resource in [self.framebuffer, self.depth, *self.textures]:
            if resource is not None:
                resource.release()
        self.textures, self.depth, self.framebuffer = [], None, None

    def release(self):
        self._release_targets()
        self.program.release()
