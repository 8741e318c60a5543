"""Running the radiance schedule's work items (engine/frame/schedule.py): each kind of item is
run by the pass it names (WORK_ITEMS), over the voxel segments its selection resolves to
(segments.py), under that pass's timer. A part of the Renderer, whose grid, passes, class index
and schedule it uses; the renderer decides which plans run in a frame."""
from dataclasses import dataclass

from . import schedule
from .segments import cell_segments, gather_segments, sky_segments, voxel_segment


@dataclass(frozen=True)
class WorkResources:
    """What the radiance schedule's work items read besides the grid, for one frame."""
    shadow_maps: object
    emitters: object
    environment: object
    cone_uniforms: object  # RenderSettings.cone_uniforms: the uniforms of lib/cone.glsl for a diffuse cone set


class WorkItems:
    """The Renderer's running of work items (a base class of it)."""

    def _run(self, plan, work):
        """Run the work items a plan of the radiance schedule yields, each under the timer of
        its pass; returns the items run."""
        def execute(item):
            with self.timed(item.timer):
                return self._execute(item, work)
        return schedule.run_plan(plan, execute)

    def _gathered(self, index=None):
        """Gather array `index` (None: the latest)."""
        return self.gather.gathered[self.schedule.latest if index is None else index]

    def _cones(self):
        """What a program tracing cones binds: the voxels and the light they reflect."""
        return self.faces.cones(self.grid)

    def _execute(self, item, work):
        """Run one work item of the radiance schedule with the pass that does it (WORK_ITEMS);
        returns what a MeasureTotals or ReadTotals measured, else None."""
        return WORK_ITEMS[type(item)](self, item, work)

    def _sort_classes(self, item, work):
        self.class_index = self.gather.sort_classes(self.grid, item.interleave)

    def _find_anchors(self, item, work):
        self.gather.find_anchors(self.grid)

    def _inject(self, item, work):
        segment = voxel_segment(self.grid, self.class_index, item.voxels)
        self.inject.run(self.grid, work.shadow_maps, segment, self.emitter_light.irradiance, self.sky_light.irradiance)

    def _light_voxels(self, item, work):
        grid = self.grid
        if item.source == "emitter_light":
            segment = voxel_segment(grid, self.class_index, item.voxels)
            self.emitter_light.run(grid, self._cones(), work.emitters, work.cone_uniforms(), segment, item.levels)
            return
        segments = sky_segments(grid, self.class_index, item.voxels)
        levels = range(grid.levels) if item.levels is None else item.levels
        self.sky_light.run(grid, self._cones(), work.environment, work.cone_uniforms(), segments.traced, self.gather.anchors,
                           levels, item.box)
        self.sky_light.fill(grid, self.gather.anchors, segments.filled, segments.finer)
        self.sky_light.filter(grid, segments.filtered, levels, item.box)

    def _take_coarser_sky_light(self, item, work):
        self.sky_light.take_coarser(self.grid, voxel_segment(self.grid, self.class_index, item.voxels), sorted(item.levels))

    def _compose_faces(self, item, work):
        gathered = None if item.gathered is None else self._gathered(item.gathered)
        for voxels in item.voxels:
            self.faces.compose(self.grid, self.inject.base, gathered, voxel_segment(self.grid, self.class_index, voxels),
                               voxels.levels)

    def _mipmap(self, item, work):
        cells = [segment for voxels in item.voxels for segment in cell_segments(self.grid, self.class_index, voxels)]
        self.faces.mipmap(self.grid, cells, item.levels)

    def _gather(self, item, work):
        segments = gather_segments(self.grid, self.class_index, item.voxels)
        self.gather.run(self.grid, self._cones(), work.cone_uniforms(item.cones), self._gathered(item.into), segments.traced,
                        segments.filled, segments.finer, self.sky_light.irradiance, item.part, item.parts)

    def _extrapolate_gather(self, item, work):
        self.gather.extrapolate(self.grid, self._gathered(item.latest), self._gathered(item.older), item.gain)

    def _measure_totals(self, item, work):
        return self.faces.totals(self.grid)

    def _request_totals(self, item, work):
        self.faces.request_totals(self.grid)

    def _read_totals(self, item, work):
        return self.faces.read_totals()


# The method that runs each kind of work item of the radiance schedule with its pass.
WORK_ITEMS = {
    schedule.SortClasses: WorkItems._sort_classes,
    schedule.FindAnchors: WorkItems._find_anchors,
    schedule.Inject: WorkItems._inject,
    schedule.LightVoxels: WorkItems._light_voxels,
    schedule.TakeCoarserSkyLight: WorkItems._take_coarser_sky_light,
    schedule.ComposeFaces: WorkItems._compose_faces,
    schedule.Mipmap: WorkItems._mipmap,
    schedule.Gather: WorkItems._gather,
    schedule.ExtrapolateGather: WorkItems._extrapolate_gather,
    schedule.MeasureTotals: WorkItems._measure_totals,
    schedule.RequestTotals: WorkItems._request_totals,
    schedule.ReadTotals: WorkItems._read_totals,
}
