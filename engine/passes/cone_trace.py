"""Cone-tracing pass: the image over the G-buffer. Direct light (with emission) plus the
diffuse gather of the voxels interpolated per pixel (traced per pixel where no voxel faces the
pixel's way), plus a specular cone per pixel; or per-pixel AO cones."""
from ..constants import TEXTURE_UNIT
from .target import ScreenTarget

OUTPUT_KIND = {"radiance": 0, "ao": 1}


class ConeTracePass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="fullscreen.vert", fragment_shader="cone_trace.frag")
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def render(self, gbuffer, direct, grid, gathered, cone_uniforms, camera_position, terms, ao_distance):
        """`terms`: settings.ImageTerms (which of direct, diffuse, specular, or AO)."""
        gbuffer.use()
        grid.use_surface()
        grid.use_faces()
        gathered.use(TEXTURE_UNIT["VOXEL_GATHERED"])
        direct.texture.use(TEXTURE_UNIT["DIRECT_LIGHT"])
        self.program.set(**grid.uniforms(), **cone_uniforms, camera_position=tuple(camera_position),
                         output_kind=OUTPUT_KIND["ao" if terms.ao else "radiance"], include_direct=terms.direct,
                         include_diffuse=terms.diffuse, include_specular=terms.specular, ao_distance=float(ao_distance))
        self.target.draw(self.program)
        return self.target

    def release(self):
        self.target.release()
        self.program.release()
