"""The emitters' light at the voxels: per covered voxel, the irradiance from every emissive
triangle at its surface point (Lambert's polygon formula), shadowed by one cone per patch
through the face views (which must hold the grid's current coverage), and the fraction of it
that arrives, which the image interpolates per pixel. Runs over a segment of the grid's class
list when the voxels or the emitters change; light injection adds it to the base radiance."""
from ..voxels.grid import VoxelGrid
from ..voxels.records import RecordArrays


class EmitterLightPass:
    def __init__(self, ctx, programs):
        self.program = programs.compute(
            "emitter_light/light_voxels.comp", writes=("SSBO_VOXEL_EMITTER_IRRADIANCE",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.CONE_READS, "SSBO_EMITTER_TRIANGLES",
                   "SSBO_EMITTER_PATCHES"))
        self.values = RecordArrays(1)  # the emitters' light, per record, where the scene has emitters

    def hold(self, records, wanted):
        """Hold the emitters' light for the grid's `records` where `wanted` (zero when made),
        none otherwise; True when made now (the light is still to compute)."""
        return self.values.hold(records, wanted)

    @property
    def irradiance(self):
        """The emitters' shadowed irradiance per record (a: the fraction that arrives); None
        where the scene has no emitter."""
        return self.values.arrays[0] if self.values.arrays else None

    def run(self, grid, cones, emitters, cone_uniforms, segment, levels=None):
        """`cones`: what cones read (FaceViewsPass.cones); `emitters`:
        scene_buffers.EmitterBuffers; `segment`: a VoxelSegment of the class list, lit where
        they lie in `levels` (None: every level). Writes the emitters' light at those voxels and
        returns it."""
        self.program.set(**grid.uniforms(), **cone_uniforms, **emitters.uniforms(), lit_levels=grid.level_mask(levels))
        grid.dispatch(self.program, segment, SSBO_VOXEL_LIST=segment.buffer, **cones, **emitters.resources(),
                      SSBO_VOXEL_EMITTER_IRRADIANCE=self.irradiance)
        return self.irradiance

    def memory_bytes(self):
        return self.values.memory_bytes()

    def release(self):
        self.values.release()
        self.program.release()
