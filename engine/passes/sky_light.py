"""The environment's light at the voxels: the sky's irradiance at a voxel's surface point through
SKY_CONE_COUNT cones over its hemisphere, each bringing the sky around its direction as far as
the voxels let it through (the face views must hold the grid's current coverage), each voxel's
cones offset by a jitter of its own. Traced at the gather's anchors of a segment of the class
list when the voxels or the environment change (or of the voxels a scrolled level took in) into
its traced irradiance, the other voxels interpolating them as they interpolate the gather
(AnchorFill); then averaged over the like-facing voxels around each covered voxel (or each of
those taken in) into its irradiance, which light injection adds to the base radiance and the
image interpolates per pixel. The voxels a scrolled clipmap level took
in may take theirs from the next coarser level instead (take_coarser), until the camera rests."""
import numpy as np

from ..voxels.grid import VoxelGrid
from ..voxels.records import RecordArrays
from .gather import AnchorFill


class SkyLightPass:
    def __init__(self, ctx, programs):
        self.program = programs.compute(
            "sky_light/trace_sky_cones.comp", writes=("SSBO_VOXEL_TRACED_SKY_IRRADIANCE",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", "SSBO_GATHER_ANCHORS", *VoxelGrid.CONE_READS, "TEX_ENVIRONMENT"))
        self.filter_program = programs.compute(
            "sky_light/filter_sky_light.comp", writes=("SSBO_VOXEL_SKY_IRRADIANCE",),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS, "SSBO_VOXEL_TRACED_SKY_IRRADIANCE"))
        self.coarser_program = programs.compute(
            "sky_light/take_coarser_sky_light.comp", writes=("SSBO_VOXEL_TRACED_SKY_IRRADIANCE", "SSBO_VOXEL_SKY_IRRADIANCE"),
            reads=("SSBO_VOXEL_LIST", "SSBO_SEGMENTS", *VoxelGrid.SURFACE_READS, "SSBO_VOXEL_SKY_IRRADIANCE"))
        self.values = RecordArrays(2)  # the sky's irradiance per record, filtered and traced, where the scene has a sky
        self.filling = AnchorFill(programs)

    def hold(self, records, wanted):
        """Hold the sky's light for the grid's `records` where `wanted` (zero when made), none
        otherwise; True when made now (the light is still to compute)."""
        return self.values.hold(records, wanted)

    @property
    def irradiance(self):
        """The sky's irradiance per record, filtered (what light injection and the image
        read); None where the scene has no sky."""
        return self.values.arrays[0] if self.values.arrays else None

    @property
    def traced(self):
        """The sky's irradiance per record as the anchors' cones brought it (and the other
        voxels interpolated it); None where the scene has no sky."""
        return self.values.arrays[1] if self.values.arrays else None

    def run(self, grid, cones, environment, cone_uniforms, segment, anchors, levels=None, box=None):
        """`cones`: what cones read (FaceViewsPass.cones); `environment`:
        scene_buffers.EnvironmentMap; `segment`: a VoxelSegment (the anchors of a
        class, or the voxels a voxelization touched), whose anchors (`anchors`: the gather's
        anchor words, GatherPass.anchors) are lit where they lie in `levels` (None: every
        level) and their centres in the world box `box` ((lo, hi); None: anywhere). Writes and
        returns the traced irradiance, at those voxels."""
        self.program.set(**grid.uniforms(), **cone_uniforms, **environment.uniforms(), lit_levels=grid.level_mask(levels),
                         **_box_uniforms(box))
        grid.dispatch(self.program, segment, SSBO_VOXEL_LIST=segment.buffer, SSBO_GATHER_ANCHORS=anchors, **cones,
                      **environment.resources(), SSBO_VOXEL_TRACED_SKY_IRRADIANCE=self.traced)
        return self.traced

    def fill(self, grid, anchors, filled, finer):
        """The traced irradiance of the voxels that are not anchors, from the anchors' as the
        gather fills its own (AnchorFill; `anchors`: GatherPass.anchors). Returns it."""
        return self.filling.run(grid, self.traced, anchors, filled, finer)

    def filter(self, grid, segment, levels=None, box=None):
        """The filtered irradiance of the voxels of `segment` (a VoxelSegment: the covered list, or
        the voxels a voxelization touched) that lie in `levels` (None: every level; a voxel's
        filter reads its own level only) and within the filter's reach of the world box `box`
        (the voxels lit in it; None: anywhere) from the traced irradiance around each (written
        and returned)."""
        self.filter_program.set(**grid.uniforms(), lit_levels=grid.level_mask(levels), **_box_uniforms(box))
        grid.dispatch(self.filter_program, segment, SSBO_VOXEL_LIST=segment.buffer, **grid.surface(),
                      SSBO_VOXEL_TRACED_SKY_IRRADIANCE=self.traced, SSBO_VOXEL_SKY_IRRADIANCE=self.irradiance)
        return self.irradiance

    def take_coarser(self, grid, segment, levels):
        """The sky's light at the voxels of `segment` (the voxels a scroll took in) that lie in
        `levels` (each finer than the coarsest), from the next coarser level's filtered
        irradiance around them: a lookup in place of their cones. Writes it as their traced and
        filtered irradiance; returns the latter."""
        self.coarser_program.set(**grid.uniforms(), lit_levels=grid.level_mask(levels))
        grid.dispatch(self.coarser_program, segment, SSBO_VOXEL_LIST=segment.buffer, **grid.surface(),
                      SSBO_VOXEL_TRACED_SKY_IRRADIANCE=self.traced, SSBO_VOXEL_SKY_IRRADIANCE=self.irradiance)
        return self.irradiance

    def memory_bytes(self):
        return self.values.memory_bytes()

    def release(self):
        self.values.release()
        self.filling.release()
        self.program.release()
        self.filter_program.release()
        self.coarser_program.release()


def _box_uniforms(box):
    """The uniforms lit_box_min and lit_box_max of a world box (lo, hi); None: all of space."""
    lo, hi = box if box is not None else (np.full(3, -np.inf), np.full(3, np.inf))
    return dict(lit_box_min=tuple(float(c) for c in lo), lit_box_max=tuple(float(c) for c in hi))
