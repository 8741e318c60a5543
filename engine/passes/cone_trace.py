"""Cone-tracing pass: the image over the G-buffer. Direct light (with emission, and the light of
emissive surfaces shadowed through the voxels) plus the diffuse gather of the voxels
interpolated per pixel, plus a specular cone traced at every other pixel in x and y and shared
with the pixels between; or per-pixel AO cones. Pixels that need cones (specular surfaces,
thin surfaces seen from behind, which no voxel faces and whose diffuse cones are shared the
same way, and every pixel for AO) are listed and traced by compute passes, so the other pixels
never wait on them: the anchors and unshared cones first, then the pixels between anchors,
then those of them that no anchor stood for."""
import numpy as np

from ..core.constants import GL_IMAGE_FORMAT, SHADER_ENUMS
from ..gpu.bindings import Image
from ..gpu.functions import write_buffer
from ..voxels.grid import VoxelGrid
from .gbuffer import GBuffer
from .target import ScreenTarget



class ConeTracePass:
    def __init__(self, ctx, programs, size):
        self.ctx = ctx
        # The image's programs, by whether surfaces emit (EMITTERS) and whether the scene has an
        # environment (SKY).
        # Each binds the three pixel lists (lib/cone_pixels.glsl declares them together).
        self.programs = {(lit, sky): programs.program(
            {name: 1 for name, on in (("EMITTERS", lit), ("SKY", sky)) if on} or None,
            vertex_shader="lib/fullscreen.vert", fragment_shader="cone_trace/shade_pixels.frag",
            reads=(*GBuffer.READS, "UBO_CAMERA", "TEX_DIRECT_LIGHT", *VoxelGrid.CONE_READS, "SSBO_VOXEL_GATHERED",
                   "SSBO_VOXEL_EMITTER_IRRADIANCE", "SSBO_VOXEL_SKY_IRRADIANCE", "TEX_ENVIRONMENT", "SSBO_EMITTER_TRIANGLES",
                   "SSBO_EMITTER_PATCHES", "SSBO_UNSHARED_PIXELS"),
            writes=("SSBO_CONE_PIXELS", "SSBO_SHARED_PIXELS", "IMG_DIFFUSE_IN"))
            for lit in (False, True) for sky in (False, True)}
        # The traced pixels' programs: the cone pixels', then the unshared pixels'.
        self.traced_programs = [programs.compute(
            "cone_trace/trace_listed_pixels.comp", defines,
            reads=(*GBuffer.READS, "UBO_CAMERA", *VoxelGrid.CONE_READS, "TEX_VOXEL_CONE_EMISSION", "TEX_ENVIRONMENT", "SSBO_CONE_PIXELS",
                   "SSBO_SHARED_PIXELS", "SSBO_UNSHARED_PIXELS"),
            writes=("IMG_IMAGE_OUT", "IMG_DIFFUSE_IN", "IMG_SPECULAR_IN")) for defines in (None, {"TRACE_UNSHARED": 1})]
        self.shared_program = programs.compute(
            "cone_trace/share_anchor_cones.comp", reads=(*GBuffer.READS, "UBO_CAMERA", *VoxelGrid.CONE_READS, "SSBO_CONE_PIXELS", "SSBO_SHARED_PIXELS",
                                                          "IMG_DIFFUSE_IN", "IMG_SPECULAR_IN"),
            writes=("SSBO_UNSHARED_PIXELS", "IMG_IMAGE_OUT"))
        self.target = ScreenTarget(ctx, size)
        self.cone_pixels = self.shared_pixels = self.unshared_pixels = self.specular_in = self.diffuse_in = None
        self.resize(size)

    def resize(self, size):
        self.target.resize(size)
        for resource in (self.cone_pixels, self.shared_pixels, self.unshared_pixels, self.specular_in, self.diffuse_in):
            if resource is not None:
                resource.release()
        # The pixel lists (lib/cone_pixels.glsl): a header of 16 bytes, then 8 bytes a pixel.
        self.cone_pixels, self.shared_pixels, self.unshared_pixels = (
            self.ctx.buffer(reserve=16 + 8 * size[0] * size[1]) for _ in range(3))
        # The anchors' specular Lv and diffuse gather: one texel per anchor pixel (even x and y).
        anchors = ((size[0] + 1) // 2, (size[1] + 1) // 2)
        self.specular_in, self.diffuse_in = (self.ctx.texture(anchors, 4, dtype="f4") for _ in range(2))

    def render(self, gbuffer, direct, grid, *, cones, gathered, emitter_irradiance, sky_irradiance, emitters, environment,
               cone_uniforms, camera, terms, ao_distance):
        """The HDR image over the G-buffer `gbuffer` and the direct light `direct`, from `grid`'s
        voxels as cones read them (`cones`: FaceViewsPass.cones), the light they gathered and
        the emitters' and the sky's light at them (arrays per record; the latter two None where
        the scene has none). `camera`: frame.camera.FrameCamera; `emitters`:
        gpu.scene_buffers.EmitterBuffers; `environment`: gpu.scene_buffers.EnvironmentMap;
        `terms`: settings.ImageTerms (which of direct, diffuse, specular, or AO)."""
        program = self.programs[emitters.count > 0, environment.environment is not None]
        for handle in (program, *self.traced_programs, self.shared_program):
            handle.set(**environment.uniforms())
        grid_uniforms = dict(grid.uniforms(), voxel_emitters=emitters.count > 0)
        listed_terms = dict(include_diffuse=terms.diffuse, include_specular=terms.specular)  # lib/cone_pixels.glsl
        program.set(**grid_uniforms, **cone_uniforms, **emitters.uniforms(), **listed_terms,
                    output_kind=SHADER_ENUMS["OUTPUT"]["ao" if terms.ao else "radiance"], include_direct=terms.direct,
                    pixel_angle=float(camera.pixel_angle))
        for pixel_list in (self.cone_pixels, self.shared_pixels, self.unshared_pixels):
            write_buffer(pixel_list, np.array([0, 1, 1, 0], dtype="u4").tobytes())  # no group, no pixel yet
        rgba32f = GL_IMAGE_FORMAT["rgba32f"]
        # What every program of the pass reads: the G-buffer, the camera, the voxels cones read.
        common = {**gbuffer.resources(), **camera.resources(), **cones}
        pixels = dict(SSBO_CONE_PIXELS=self.cone_pixels, SSBO_SHARED_PIXELS=self.shared_pixels,
                      SSBO_UNSHARED_PIXELS=self.unshared_pixels)
        anchors = dict(IMG_DIFFUSE_IN=Image(self.diffuse_in, read=True, write=True, format=rgba32f),
                       IMG_SPECULAR_IN=Image(self.specular_in, read=True, write=True, format=rgba32f))
        self.target.draw(program, {**common, **pixels, "IMG_DIFFUSE_IN": anchors["IMG_DIFFUSE_IN"],
                                   "TEX_DIRECT_LIGHT": direct.texture, "SSBO_VOXEL_GATHERED": gathered,
                                   "SSBO_VOXEL_EMITTER_IRRADIANCE": emitter_irradiance,
                                   "SSBO_VOXEL_SKY_IRRADIANCE": sky_irradiance, **environment.resources(),
                                   **emitters.resources()})
        if terms.diffuse or terms.specular or terms.ao:
            self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.COMMAND_BARRIER_BIT
                                    | self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT)
            image_out = Image(self.target.texture, read=True, write=True, format=rgba32f)
            barrier = (self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.TEXTURE_FETCH_BARRIER_BIT
                       | self.ctx.SHADER_STORAGE_BARRIER_BIT | self.ctx.COMMAND_BARRIER_BIT)
            cone_program, unshared_program = self.traced_programs
            traced = {**common, **pixels, **anchors, "IMG_IMAGE_OUT": image_out, "TEX_VOXEL_CONE_EMISSION": grid.cone_emission,
                      **environment.resources()}
            shared = {**common, **pixels, **anchors, "IMG_IMAGE_OUT": image_out}
            # The anchors first, then the pixels between them, then those no anchor stood for.
            for handle, pixel_list, resources in ((cone_program, self.cone_pixels, traced), (self.shared_program, self.shared_pixels, shared),
                                                  (unshared_program, self.unshared_pixels, traced)):
                handle.set(**grid_uniforms, **cone_uniforms, **listed_terms, ao_distance=float(ao_distance))
                handle.run_indirect(pixel_list, **resources)
                self.ctx.memory_barrier(barrier)
        return self.target

    def release(self):
        for resource in (self.target, *self.programs.values(), *self.traced_programs, self.shared_program,
                         self.cone_pixels, self.shared_pixels, self.unshared_pixels, self.specular_in, self.diffuse_in):
            resource.release()
