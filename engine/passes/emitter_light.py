"""The emitters' light at the voxels: per covered voxel, the irradiance from every emissive
triangle at its surface point (Lambert's polygon formula), shadowed by one cone per patch
through the face views (which must hold the grid's current coverage), and the fraction of it
that arrives, which the image interpolates per pixel. Runs over a segment of the grid's class
list when the voxels or the emitters change; light injection adds it to the base radiance."""
from ..voxels.grid import VoxelGrid


class EmitterLightPass:
    def __init__(self, ctx, programs):
        self.program = programs.compute(
            "emitter_light/light_voxels.comp", writes=("SSBO_VOXEL_EMITTER_IRRADIANCE",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.CONE_READS, "SSBO_EMITTER_TRIANGLES",
                   "SSBO_EMITTER_PATCHES"))

    def run(self, grid, emitters, cone_uniforms, segment, levels=None):
        """`emitters`: scene_buffers.EmitterBuffers; `segment`: a VoxelSegment of the class list,
        lit where they lie in `levels` (None: every level). Writes and returns
        grid.emitter_irradiance, at those voxels."""
        self.program.set(**grid.uniforms(), **cone_uniforms, **emitters.uniforms(), lit_levels=grid.level_mask(levels))
        grid.dispatch(self.program, segment, SSBO_VOXEL_LIST=segment.buffer, **grid.cones(), **emitters.resources(),
                      SSBO_VOXEL_EMITTER_IRRADIANCE=grid.emitter_irradiance)
        return grid.emitter_irradiance

    def release(self):
        self.program.release()
