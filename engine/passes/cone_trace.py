"""Cone-tracing pass: a fullscreen pass over the G-buffer that traces the diffuse (6 cones),
specular (1 cone) and AO cones through the mipmapped voxel radiance and composites them with
the direct light."""
from ..constants import TEXTURE_UNIT
from .target import ScreenTarget
from .voxelize import use_faces

OUTPUT_KIND = {"radiance": 0, "ao": 1}


class ConeTracePass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="fullscreen.vert", fragment_shader="cone_trace.frag")
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def render(self, voxel_uniforms, cone_uniforms, face_volumes, direct_texture, camera_position, *,
               ao=False, direct=True, diffuse=True, specular=True, ao_distance=1.0):
        use_faces(face_volumes)
        direct_texture.use(TEXTURE_UNIT["DIRECT_LIGHT"])
        self.program.set(**voxel_uniforms, **cone_uniforms, camera_position=tuple(camera_position),
                         output_kind=OUTPUT_KIND["ao" if ao else "radiance"], include_direct=direct,
                         include_diffuse=diffuse, include_specular=specular, ao_distance=float(ao_distance))
        self.target.draw(self.program)

    def release(self):
        self.target.release()
        self.program.release()
