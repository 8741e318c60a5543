"""G-buffer pass: rasterizes the draws from the camera into position, shading normal +
roughness, albedo + metalness and emission + dielectric F0 targets (material factors times
textures), with a depth buffer; back faces of single-sided materials are culled. Returns the
GBuffer the screen passes read."""
from .. import transforms
from ..constants import HDR_FORMAT
from ..gl_bindings import bind_texture
from ..scene_gpu import vertex_extras


class GBuffer:
    """The G-buffer targets; `use()` binds them where glsl/lib/gbuffer.glsl reads them."""

    UNITS = ("GBUF_POSITION", "GBUF_NORMAL", "GBUF_ALBEDO", "GBUF_EMISSION")
    READS = tuple(f"TEX_{unit}" for unit in UNITS)  # what a program reading all of them declares

    def __init__(self, ctx, size):
        self.size = size
        self.textures = [ctx.texture(size, 4, dtype=HDR_FORMAT if name == "GBUF_POSITION" else "f2")
                         for name in self.UNITS]
        for texture in self.textures:
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
        self.depth = ctx.depth_texture(size)
        self.framebuffer = ctx.framebuffer(color_attachments=self.textures, depth_attachment=self.depth)

    def use(self):
        for name, texture in zip(self.UNITS, self.textures):
            bind_texture(texture, name)

    def release(self):
        for resource in [self.framebuffer, self.depth, *self.textures]:
            resource.release()


class GBufferPass:
    def __init__(self, ctx, programs, geometry, size):
        self.ctx = ctx
        self.geometry = geometry
        # Per whether the material has a normal map (else no tangent is interpolated) and the draw
        # vertex colours, a second texture coordinate set or texture transforms (else none).
        self.programs = {(mapped, extras): programs.program(
            {name: 1 for name, wanted in (("NORMAL_MAP", mapped), ("VERTEX_EXTRAS", extras)) if wanted},
            vertex_shader="gbuffer/draw_surfaces.vert", fragment_shader="gbuffer/draw_surfaces.frag",
            reads=("TEX_BASE_COLOR_MAP", "TEX_METAL_ROUGH_MAP", "TEX_EMISSIVE_MAP", "TEX_NORMAL_MAP"))
            for mapped in (False, True) for extras in (False, True)}
        self.target = GBuffer(ctx, size)

    def resize(self, size):
        self.target.release()
        self.target = GBuffer(self.ctx, size)

    def render(self, draws, view_projection):
        gbuffer = self.target
        gbuffer.framebuffer.use()
        self.ctx.viewport = (0, 0, *gbuffer.size)
        gbuffer.framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable_only(self.ctx.DEPTH_TEST)
        for (mapped, extras), program in self.programs.items():
            subset = [draw for draw in draws if (draw.material.normal_texture is not None) == mapped
                      and vertex_extras(draw) == extras]
            if subset:
                program.set(view_projection=transforms.gl_bytes(view_projection))
                self.geometry.draw(program, subset, materials=True, cull_single_sided=True, view_projection=view_projection)
        return gbuffer

    def release(self):
        self.target.release()
        for program in self.programs.values():
            program.release()
