"""Cone-tracing pass: over the G-buffer, the 6 diffuse/AO cones are traced at half resolution
and upsampled edge-aware; the specular cone is traced per pixel; both are composited with the
direct light."""
from ..constants import TEXTURE_UNIT
from .target import ScreenTarget
from .voxelize import use_faces

OUTPUT_KIND = {"radiance": 0, "ao": 1}
EVERYWHERE = 1e9  # gather distance of light cones: until they are opaque or leave the grid


def half_size(size):
    return ((size[0] + 1) // 2, (size[1] + 1) // 2)


class ConeTracePass:
    def __init__(self, ctx, programs, size):
        self.gather_program = programs.program(vertex_shader="fullscreen.vert", fragment_shader="cone_gather.frag")
        self.program = programs.program(vertex_shader="fullscreen.vert", fragment_shader="cone_trace.frag")
        self.gather = ScreenTarget(ctx, half_size(size))
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.gather.resize(half_size(size))
        self.target.resize(size)

    def render(self, voxel_uniforms, cone_uniforms, face_volumes, direct_texture, camera_position, *,
               ao=False, direct=True, diffuse=True, specular=True, ao_distance=1.0):
        use_faces(face_volumes)
        gather_distance = float(ao_distance) if ao else EVERYWHERE
        if ao or diffuse:
            self.gather_program.set(**voxel_uniforms, **cone_uniforms, gather_distance=gather_distance)
            self.gather.draw(self.gather_program)
        self.gather.texture.use(TEXTURE_UNIT["DIFFUSE_GATHER"])
        direct_texture.use(TEXTURE_UNIT["DIRECT_LIGHT"])
        self.program.set(**voxel_uniforms, **cone_uniforms, camera_position=tuple(camera_position),
                         output_kind=OUTPUT_KIND["ao" if ao else "radiance"], include_direct=direct,
                         include_diffuse=diffuse, include_specular=specular, gather_distance=gather_distance)
        self.target.draw(self.program)

    def release(self):
        for resource in (self.gather, self.target, self.gather_program, self.program):
            resource.release()
