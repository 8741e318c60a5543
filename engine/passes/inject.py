"""Light injection: the base radiance of every covered voxel, emission plus the direct light
its surface receives from every light (with the shadow maps), evaluated per voxel at its
surface point, and from the emitters (passes/emitter_light.py). Runs when lights, shadows,
the emitters' light or the voxels change, over a segment of a voxel list."""
from ..voxels.grid import VoxelGrid
from ..voxels.records import RecordArrays


class InjectPass:
    def __init__(self, ctx, programs):
        self.program = programs.compute(
            "inject/inject_direct_light.comp", writes=("SSBO_VOXEL_BASE",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS, "SSBO_VOXEL_EMITTER_IRRADIANCE",
                   "SSBO_VOXEL_SKY_IRRADIANCE", "TEX_SHADOW_ATLAS", "UBO_LIGHTS", "UBO_SHADOW_VIEWS"))
        self.values = RecordArrays(1)  # the base radiance, per record

    def hold(self, records):
        """Hold the base radiance for the grid's `records` (zero when made); True when made now."""
        return self.values.hold(records)

    @property
    def base(self):
        """The base radiance per record (emission + injected direct light), what it wrote."""
        return self.values.arrays[0]

    def run(self, grid, shadow_maps, segment, emitter_irradiance=None, sky_irradiance=None):
        """Writes the base radiance of the voxels of `segment` (a VoxelSegment), adding the
        emitters' and the sky's irradiance at the voxels (arrays per record of their passes)
        where the scene has them; returns it."""
        self.hold(grid.records)
        self.program.set(**grid.uniforms(), **shadow_maps.uniforms(), voxel_emitters=emitter_irradiance is not None,
                         voxel_sky=sky_irradiance is not None)
        grid.dispatch(self.program, segment, SSBO_VOXEL_LIST=segment.buffer, **grid.surface(),
                      SSBO_VOXEL_EMITTER_IRRADIANCE=emitter_irradiance, SSBO_VOXEL_SKY_IRRADIANCE=sky_irradiance,
                      **shadow_maps.resources(), SSBO_VOXEL_BASE=self.base)
        return self.base

    def memory_bytes(self):
        return self.values.memory_bytes()

    def release(self):
        self.values.release()
        self.program.release()
