"""The environment's light at the voxels: the sky's irradiance at a voxel's surface point through
SKY_CONE_COUNT cones over its hemisphere, each bringing the sky around its direction as far as
the voxels let it through (the face views must hold the grid's current coverage). Traced at the
gather's anchors of a segment of the class list when the voxels or the environment change; the
other voxels interpolate them as they interpolate the gather (GatherPass.fill). Light injection
adds it to the base radiance, and the image interpolates it per pixel."""
from ..constants import IMAGE_UNIT, STORAGE_BINDING
from ..voxel_grid import bind_image


class SkyLightPass:
    def __init__(self, ctx, programs):
        self.program = programs.compute("voxel_sky_light.comp")

    def run(self, grid, environment, cone_uniforms, segment):
        """`environment`: scene_gpu.EnvironmentMap; `segment`: a VoxelSegment of the class list
        (the anchors of a class). Writes grid.sky_light for those voxels."""
        grid.use_surface()
        grid.use_faces()
        segment.buffer.bind_to_storage_buffer(STORAGE_BINDING["VOXEL_LIST"])
        environment.bind(self.program)
        bind_image(grid.sky_light, IMAGE_UNIT["SKY_LIGHT_OUT"])
        self.program.set(**grid.uniforms(), **cone_uniforms, first=segment.first, count=segment.count)
        grid.dispatch(self.program, segment.count)

    def release(self):
        self.program.release()
