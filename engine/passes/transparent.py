"""Transparency pass: the blended draws (alphaMode BLEND), which the G-buffer leaves out, shaded
per fragment and seen over the opaque image by weighted, blended order-independent
transparency (McGuire and Bavoil 2013; glsl/transparent/). Why that and not sorted layers: it
needs no sorting (of draws, or of the triangles of one mesh that overlaps itself), one pass
and two targets whatever the depth complexity, and it is exact for one layer, the case that
matters most (a window, a visor); where several layers overlap, their colours mix by weights
that favour the nearer, not in strict order. What lies behind the opaque surfaces is hidden by
the G-buffer's depth. The shadow maps and the voxels see blended surfaces dissolved with
probability 1 - alpha (lib/material.glsl), so a pane of alpha 0.5 lets through about half the
light, direct and indirect."""
import numpy as np

from ..core.constants import DRAW_TEST_FRUSTUM
from ..gpu.functions import gl_functions
from ..gpu.scene_buffers import DRAW_FLAGS
from ..voxels.grid import VoxelGrid
from .cull import DrawList, view_records
from .gbuffer import GBufferPass, culling_faces, face_culling
from .target import ScreenTarget

GL_ONE, GL_ONE_MINUS_SRC_COLOR = 1, 0x0301
DRAW_READS = ("UBO_CAMERA", "SSBO_DRAWS", "SSBO_MATERIALS", "TEX_MATERIAL_TEXTURES", "UBO_LIGHTS", "UBO_SHADOW_VIEWS",
              "TEX_SHADOW_ATLAS")
VOXEL_READS = (*VoxelGrid.CONE_READS, "TEX_VOXEL_CONE_EMISSION", "SSBO_VOXEL_GATHERED", "SSBO_VOXEL_SKY_IRRADIANCE",
               "SSBO_VOXEL_EMITTER_IRRADIANCE", "TEX_ENVIRONMENT")


class TransparentPass:
    def __init__(self, ctx, programs, cull, size):
        self.ctx, self.library, self.cull = ctx, programs, cull
        self.programs = {}  # (voxels, sky) -> the blended surfaces' program, made on first use
        self.composite = programs.program(vertex_shader="lib/fullscreen.vert", fragment_shader="transparent/composite.frag",
                                          reads=("TEX_HDR_INPUT", "TEX_BLEND_SUMS", "TEX_BLEND_COVERAGE"))
        # A bucket per face culling (GBufferPass.CULLING); past them, the draws that do not blend.
        self.draw_list = DrawList(ctx, self.bucket_of, len(GBufferPass.CULLING) + 1)
        self.sums = self.coverage = self.framebuffer = None
        self.target = ScreenTarget(ctx, size)
        self.resize(size, None)

    @staticmethod
    def bucket_of(flags):
        return np.where(flags & DRAW_FLAGS["blended"], face_culling(flags), len(GBufferPass.CULLING))

    def resize(self, size, gbuffer):
        """Targets of `size`, depth-tested against `gbuffer` (made where it is given)."""
        self.target.resize(size)
        for resource in (self.framebuffer, self.sums, self.coverage):
            if resource is not None:
                resource.release()
        self.sums = self.ctx.texture(size, 4, dtype="f4")
        self.coverage = self.ctx.texture(size, 1, dtype="f2")
        self.framebuffer = None
        self.depth_of = None
        if gbuffer is not None:
            self._framebuffer(gbuffer)

    def _framebuffer(self, gbuffer):
        if self.depth_of is not gbuffer.depth:
            if self.framebuffer is not None:
                self.framebuffer.release()
            self.framebuffer = self.ctx.framebuffer(color_attachments=[self.sums, self.coverage],
                                                    depth_attachment=gbuffer.depth)
            self.depth_of = gbuffer.depth
        return self.framebuffer

    def program(self, voxels, sky):
        key = (voxels, sky)
        if key not in self.programs:
            defines = {"NORMAL_MAP": 1, "VERTEX_EXTRAS": 1, **({"VOXELS": 1} if voxels else {}), **({"SKY": 1} if sky else {})}
            self.programs[key] = self.library.program(
                defines, vertex_shader="gbuffer/draw_surfaces.vert", fragment_shader="transparent/shade_blended.frag",
                reads=(*DRAW_READS, *(VOXEL_READS if voxels else ())))
        return self.programs[key]

    def render(self, opaque, gbuffer, buffers, camera, shadow_maps, terms, voxels=None):
        """The opaque image `opaque` (a ScreenTarget) with the blended draws of `buffers` over
        it, seen from `camera` (frame.camera.FrameCamera) and lit by `shadow_maps`' lights;
        `terms`: settings.ImageTerms; `voxels`: what the voxel light reads, a dict of
        `cones` (FaceViewsPass.cones), `gathered`, `sky_irradiance`, `emitter_irradiance`,
        `grid`, `environment` and `cone_uniforms`, or None where the frame has no voxels (direct light only)."""
        views = view_records(1)
        views["view_projection"][0] = np.asarray(camera.view_projection, "f4").T.ravel()
        self.draw_list.build(buffers)
        views["items"][0] = (0, self.draw_list.item_count, DRAW_TEST_FRUSTUM, 0)
        self.cull.run(self.draw_list, buffers, views)
        sky = voxels is not None and voxels["environment"].environment is not None
        program = self.program(voxels is not None, sky)
        resources = {**buffers.records(), **buffers.textures.resources(), **camera.resources(), **shadow_maps.resources()}
        program.set(**shadow_maps.uniforms(), include_direct=terms.direct, include_diffuse=terms.diffuse,
                    include_specular=terms.specular)
        if voxels is not None:
            program.set(**voxels["grid"].uniforms(), **voxels["cone_uniforms"], **voxels["environment"].uniforms())
            resources.update(voxels["cones"], TEX_VOXEL_CONE_EMISSION=voxels["grid"].cone_emission,
                             SSBO_VOXEL_GATHERED=voxels["gathered"],
                             SSBO_VOXEL_SKY_IRRADIANCE=voxels["sky_irradiance"],
                             SSBO_VOXEL_EMITTER_IRRADIANCE=voxels["emitter_irradiance"], **voxels["environment"].resources())
        framebuffer = self._framebuffer(gbuffer)
        framebuffer.use()
        self.ctx.viewport = (0, 0, *self.target.size)
        framebuffer.depth_mask = False  # the G-buffer's depth is read, neither cleared nor written
        framebuffer.clear(0.0, 0.0, 0.0, 0.0)
        self.ctx.enable_only(self.ctx.DEPTH_TEST | self.ctx.BLEND)
        self.ctx.depth_func = "<"
        gl = gl_functions(self.ctx)
        gl.glBlendFunci(0, GL_ONE, GL_ONE)                      # sums += w a (C, 1)
        gl.glBlendFunci(1, GL_ONE, GL_ONE_MINUS_SRC_COLOR)      # coverage = a + coverage (1 - a) = 1 - prod (1 - a)
        try:
            for bucket, culling in enumerate(GBufferPass.CULLING):
                with culling_faces(self.ctx, culling):
                    self.draw_list.draw(bucket, program, buffers, resources)
        finally:
            framebuffer.depth_mask = True
            self.ctx.blend_func = self.ctx.SRC_ALPHA, self.ctx.ONE_MINUS_SRC_ALPHA
            self.ctx.disable(self.ctx.BLEND | self.ctx.DEPTH_TEST)
        self.target.draw(self.composite, {"TEX_HDR_INPUT": opaque.texture, "TEX_BLEND_SUMS": self.sums,
                                          "TEX_BLEND_COVERAGE": self.coverage})
        return self.target

    def release(self):
        for resource in (*self.programs.values(), self.composite, self.draw_list, self.target, self.framebuffer, self.sums,
                         self.coverage):
            if resource is not None:
                resource.release()
