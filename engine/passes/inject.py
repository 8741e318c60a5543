"""Light injection: the base radiance of every covered voxel, emission plus the direct light
its surface receives from every light (with the shadow maps), evaluated per voxel at its
surface point, and from the emitters (passes/emitter_light.py). Runs when lights, shadows,
the emitters' light or the voxels change, over a segment of a voxel list."""
from ..voxels.grid import VoxelGrid


class InjectPass:
    def __init__(self, ctx, programs):
        self.program = programs.compute(
            "inject/inject_direct_light.comp", writes=("SSBO_VOXEL_BASE",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS, "SSBO_VOXEL_EMITTER_IRRADIANCE",
                   "SSBO_VOXEL_SKY_IRRADIANCE", "TEX_SHADOW_ATLAS", "UBO_LIGHTS", "UBO_SHADOW_VIEWS"))

    def run(self, grid, shadow_maps, emitters, environment, segment):
        """Writes grid.base for the voxels of `segment` (a VoxelSegment), adding the emitters'
        and the sky's irradiance at the voxels where the scene has them (`emitters`:
        scene_buffers.EmitterBuffers, `environment`: scene_buffers.EnvironmentMap)."""
        self.program.set(**grid.uniforms(), **shadow_maps.uniforms(), voxel_emitters=emitters.count > 0,
                         voxel_sky=environment.environment is not None)
        grid.dispatch(self.program, segment, SSBO_VOXEL_LIST=segment.buffer, **grid.surface(),
                      SSBO_VOXEL_EMITTER_IRRADIANCE=grid.emitter_irradiance, SSBO_VOXEL_SKY_IRRADIANCE=grid.sky_irradiance,
                      **shadow_maps.resources(), SSBO_VOXEL_BASE=grid.base)
        return grid.base

    def release(self):
        self.program.release()
