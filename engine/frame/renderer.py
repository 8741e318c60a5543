"""The renderer: the frame's data flow, pass after pass, each stage run only when its inputs
changed since it last ran (found from the scene's edits: engine/scene/table.py, engine/scene/changes.py).

    scene = engine.load_scene("scenes/cornell_box.json")
    with engine.Renderer(256, 256) as r:
        radiance = r.render(scene, mode="direct")    # float32 (H, W, 3), row 0 at the top
        r.save_png("out.png")                          # tone-mapped with the settings' curve
"""
import numbers
from contextlib import contextmanager

import moderngl
import numpy as np

from ..core.constants import SKY_NEAR_REACH
from ..core.errors import VctError
from ..core.sampling import pixel_offsets
from ..gpu.bindings import forget_bindings
from ..gpu.context import create_headless_context
from ..gpu.functions import GL_DEBUG_SOURCE_APPLICATION, gl_functions
from ..gpu.scene_buffers import EmitterBuffers, EnvironmentMap, SceneBuffers
from ..gpu.shaders import GLSL_ROOT, ProgramLibrary
from ..gpu.timing import PassTimer
from ..passes.average_samples import AverageSamplesPass
from ..passes.cone_trace import ConeTracePass
from ..passes.cull import CullPass
from ..passes.emitter_light import EmitterLightPass
from ..passes.faces import FaceViewsPass
from ..passes.gather import GatherPass
from ..passes.gbuffer import GBufferPass
from ..passes.gbuffer_view import GBufferViewPass
from ..passes.inject import InjectPass
from ..passes.lighting import LightingPass
from ..passes.pose import PosePass
from ..passes.shadow import ShadowPass
from ..passes.sky_light import SkyLightPass
from ..passes.temporal import TemporalPass
from ..passes.tonemap import TonemapPass
from ..passes.transparent import TransparentPass
from ..passes.voxel_view import VoxelViewPass, shown_values
from ..passes.voxelize import VoxelizePass
from ..scene.changes import FrameInputs, HeldDraws, Stage, VoxelUpdate
from ..scene.emitters import frame_emitters
from ..scene.model import Scene
from ..scene.table import SceneTable
from ..voxels.clipmap import frame_levels, level_shift, moved_levels, scrolled_regions, with_coarser_levels
from ..voxels.grid import VoxelGrid
from ..voxels.inspection import VoxelInspection
from . import schedule
from .camera import CameraBlock, frame_camera
from .readback import Readback, current
from .settings import RenderSettings
from .work_items import WorkItems, WorkResources

# The passes a frame runs whatever changed (their inputs are not tracked): a frame that ran no
# other draws what the last one drew.
EVERY_FRAME_PASSES = {"cone_trace", "transparent"}


def _image_size(width, height):
    """(width, height) as ints; VctError naming the one that is not a positive whole number."""
    for name, value in (("width", width), ("height", height)):
        if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value <= 0:
            raise VctError(f"must be a positive whole number, got {value!r}", field=name)
    return int(width), int(height)


class Renderer(WorkItems, Readback):
    def __init__(self, width, height, settings=None, ctx=None, glsl_root=GLSL_ROOT):
        self.ctx = None
        self.settings = _settings(settings or RenderSettings())
        self.size = _image_size(width, height)
        self._owns_context = ctx is None
        self._context_entered = False
        self.ctx = ctx or create_headless_context()
        self._check_size(self.size)
        self.measure = False        # when True, each pass is timed (GPU timer queries, read a few frames later)
        self.progressive = False    # bounces 0: one bounce per frame on top of the last (the viewer)
        self.track_changes = True   # False: every frame recomputes every stage (for comparison)
        self.debug_groups = False   # True: each pass is a GL debug group of its name
        self.passes_ran = []        # the passes the last frame ran, in order
        self.output = None          # the ScreenTarget holding the last frame's HDR result
        self.frame_settings = self.settings
        self.programs = ProgramLibrary(self.ctx, glsl_root)
        self.pass_timer = PassTimer(self.ctx)
        self.camera_block = CameraBlock(self.ctx)
        self.table = SceneTable()
        self.scene_buffers = SceneBuffers(self.ctx)
        self.grid = self.inspection = None
        self.emitters = EmitterBuffers(self.ctx)
        self.environment = EnvironmentMap(self.ctx)
        self._passes = []
        try:
            self.grid = VoxelGrid(self.ctx, self.programs)
            self.inspection = VoxelInspection(self.ctx, self.programs)  # the voxels read back
            with self._creating_targets(self.size):
                self._create_passes()
        except Exception:
            self.close()
            raise
        self.schedule = schedule.RadianceSchedule()
        self.class_index = None     # the covered voxels sorted into interleave classes (GatherPass.sort_classes)
        self.eye = None             # where the camera was at the last frame
        self.held = HeldDraws()     # the draws as the voxels hold them
        self._caster_bounds = None  # (table structure, the draws' bounds as the shadow maps hold them)
        self.stages = {name: Stage() for name in ("shadows", "cascades", "gbuffer", "lighting", "emitters", "environment",
                                                  "voxels", "emitter_light", "sky_light", "radiance", "bounces")}

    def _create_passes(self):
        """The passes of a frame, each with its programs and targets."""
        self.cull = self._add(CullPass(self.ctx, self.programs))
        self.pose = self._add(PosePass(self.ctx, self.programs))
        self.shadow = self._add(ShadowPass(self.ctx, self.programs, self.cull, self.settings.shadow_map_size))
        self.gbuffer = self._add(GBufferPass(self.ctx, self.programs, self.cull, self.size))
        self.transparent = self._add(TransparentPass(self.ctx, self.programs, self.cull, self.size))
        self.lighting = self._add(LightingPass(self.ctx, self.programs, self.size))
        self.gbuffer_view = self._add(GBufferViewPass(self.ctx, self.programs, self.size))
        self.voxelize = self._add(VoxelizePass(self.ctx, self.programs, self.cull))
        self.emitter_light = self._add(EmitterLightPass(self.ctx, self.programs))
        self.sky_light = self._add(SkyLightPass(self.ctx, self.programs))
        self.inject = self._add(InjectPass(self.ctx, self.programs))
        self.gather = self._add(GatherPass(self.ctx, self.programs))
        self.faces = self._add(FaceViewsPass(self.ctx, self.programs))
        self.cone_trace = self._add(ConeTracePass(self.ctx, self.programs, self.size))
        self.voxel_view = self._add(VoxelViewPass(self.ctx, self.programs, self.size))
        self.average_samples = self._add(AverageSamplesPass(self.ctx, self.programs, self.size))
        self.temporal = self._add(TemporalPass(self.ctx, self.programs, self.size))
        self.tonemap = self._add(TonemapPass(self.ctx, self.programs, self.size))

    @staticmethod
    @contextmanager
    def _creating_targets(size):
        """Render targets of a size the driver allows but cannot create (memory): a size error."""
        try:
            yield
        except (moderngl.Error, MemoryError) as exc:
            raise VctError(f"cannot create the {size[0]}x{size[1]} render targets ({exc})", field="size") from None

    def _add(self, render_pass):
        self._passes.append(render_pass)
        return render_pass

    def _check_size(self, size):
        limit = min(self.ctx.info["GL_MAX_TEXTURE_SIZE"], *self.ctx.info["GL_MAX_VIEWPORT_DIMS"])
        if max(size) > limit:
            if self._owns_context:
                self.ctx.release()
            raise VctError(f"image size {size[0]}x{size[1]} exceeds the driver's limit of {limit} pixels per side",
                           field="size")

    @current
    def resize(self, width, height):
        """Follow a new output size (all screen-space targets are recreated)."""
        size = _image_size(width, height)
        self._check_size(size)
        self.size = size
        with self._creating_targets(self.size):
            for render_pass in (self.gbuffer, self.lighting, self.gbuffer_view, self.cone_trace, self.voxel_view,
                                self.average_samples, self.temporal, self.tonemap):
                render_pass.resize(self.size)
            self.transparent.resize(self.size, self.gbuffer.target)

    @current
    def reload_shaders(self):
        """Rebuild the programs whose GLSL files changed; a failing one keeps its last good
        build. After a rebuild the next frame recomputes every stage with the new programs
        (an edit of the voxelizer or the bounce shows without a scene change). Returns
        (rebuilt count, [ShaderError]) for this poll."""
        rebuilt, errors = self.programs.reload_changed()
        if rebuilt:
            for stage in self.stages.values():
                stage.forget()
        return rebuilt, errors

    @property
    def bounce_iterations(self):
        return self.schedule.iterations

    @property
    def settled(self):
        """Whether the bounces have settled: progressive frames (the viewer) add none."""
        return self.schedule.settled

    @property
    def refining(self):
        """Whether progressive frames refine the settled gathers with the tiled cones."""
        return self.schedule.refining

    @property
    def idle(self):
        """Whether no radiance work is due: the bounces settled, and no round of the emitters'
        or the sky's light at the voxels runs or waits for the camera to rest. A frame then
        runs what its changes need alone (the screen passes where only the camera moves)."""
        return self.schedule.idle

    # -- frame ---------------------------------------------------------------------------

    @contextmanager
    def timed(self, name):
        """Around a pass: named in passes_ran, timed when measuring, and a debug group of its
        name where `debug_groups` (what GPU debuggers and apitrace show the frame by)."""
        self.passes_ran.append(name)
        if self.debug_groups:
            gl_functions(self.ctx).glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, name.encode())
        try:
            if not self.measure:
                yield
            else:
                with self.pass_timer.timed(name):
                    yield
        finally:
            if self.debug_groups:
                gl_functions(self.ctx).glPopDebugGroup()

    @property
    def timings(self):
        """Milliseconds per pass of the latest frame measured whose figures are in (on a GPU, a
        few frames back: engine/gpu/timing.py)."""
        return self.pass_timer.timings

    @current
    def render_frame(self, scene, settings=None):
        """Render one frame on the GPU; `self.output` holds the HDR result. Returns it."""
        if not isinstance(scene, Scene):
            raise VctError(f"must be an engine Scene (engine.load_scene), got {type(scene).__name__}", field="scene")
        s = _settings(settings or self.settings)
        self.frame_settings = s
        if not self._owns_context:  # GL code between frames (a window's GUI) may have bound anything
            forget_bindings(self.ctx)
        self.passes_ran = []
        self.scene_buffers.draw_calls = 0
        self.table.sync(scene, rebuild=not self.track_changes)
        self.scene_buffers.sync(self.table)
        posed = self.pose.due(self.table, self.scene_buffers)
        if self.pose.busy(posed, motion=s.temporal):
            with self.timed("pose"):
                self.pose.run(self.table, self.scene_buffers, posed, motion=s.temporal)
        frame = FrameInputs(scene, self.table)
        if self.measure:
            with self.pass_timer.frame():
                self.output = self._samples(frame, scene, s)
        else:
            self.output = self._samples(frame, scene, s)
        return self.output

    def _samples(self, frame, scene, s):
        """The frame's image: seen through the pixels' centres, or the mean of `s.samples` images
        seen through points spread over each pixel (a box filter; data views take the centres).
        The voxels and their light do not depend on the point: the first sample brings them up
        to date, the others run the screen passes alone. With `s.temporal_aa` one sample, seen
        through the point of the pixel this frame's turn gives, blended into the frames before
        (TemporalPass)."""
        def seen_through(pixel_offset):
            return self.camera_block.write(frame_camera(scene.camera, self.size, frame.bounds, pixel_offset))

        if s.temporal:
            resting = self.temporal.converged(s)
            offset = self.temporal.pixel_offset()
            camera = seen_through(offset)
            first = len(self.passes_ran)
            image = self._frame(frame, scene, s, camera)
            if resting and set(self.passes_ran[first:]) <= EVERY_FRAME_PASSES and self.idle:
                return self.temporal.held()  # the last frame's sample again: the history stands
            with self.timed("temporal"):
                return self.temporal.resolve(image, self.gbuffer.target, self.scene_buffers, camera, s, offset)
        self.temporal.forget()
        offsets = pixel_offsets(1 if s.shown.data else s.samples)
        if len(offsets) == 1:
            return self._frame(frame, scene, s, seen_through(offsets[0]))
        for count, offset in enumerate(offsets, start=1):
            image = self._frame(frame, scene, s, seen_through(offset))
            with self.timed("average_samples"):
                mean = self.average_samples.add(image, count)
        return mean

    def _frame(self, frame, scene, s, camera):
        """The passes of one frame seen by `camera` (a FrameCamera); returns the target holding
        its image."""
        resting = self.eye is not None and np.array_equal(camera.position, self.eye)
        self.eye = camera.position
        shadow_maps = self._shadows(frame, camera, scene.source)
        gbuffer = self._gbuffer(frame, camera, motion=s.temporal)
        if s.shown.stage == "gbuffer":
            with self.timed("gbuffer_view"):
                return self.gbuffer_view.render(gbuffer, s.mode, camera)
        direct = self._lighting(gbuffer, shadow_maps, camera)
        emitters = self._emitters(frame)
        environment = self._environment(frame)
        if not s.shown.uses_voxels(emitters.count > 0 or frame.environment is not None):
            return self._blended(direct, gbuffer, camera, shadow_maps, s)
        update = self._voxels(frame, s, scene.source, emitters, environment, camera)
        self._hold_values(emitters, environment)
        work = WorkResources(shadow_maps, emitters, environment, s.cone_uniforms)
        if emitters.count:
            self._voxel_light("emitter_light", work, s, update, resting, emitters=self.stages["emitters"].version)
        if environment.environment is not None:
            self._voxel_light("sky_light", work, s, update, resting, near_reach=SKY_NEAR_REACH, environment=frame.environment_values)
        if s.shown.uses_radiance:
            self._radiance(s, work, update)
            self._bounces(s, work)
        if s.shown.stage == "voxel_view":
            with self.timed("voxel_view"):
                volume = self.inspection.dense(self.grid, shown_values(self.grid, self.inject.base, s.mode))
                return self.voxel_view.render(self.grid, volume, s.mode, s.voxel_mip, self._shown_level(s), camera)
        cones, gathered = self._cones(), self._gathered()
        # The pixels' own cones: the six in progressive frames, which trace them every frame (the
        # tiled set, where named, refines the voxels' gathers once the scene rests).
        pixel_cones = s.cone_uniforms(diffuse_cones="six" if self.progressive else s.diffuse_cones)
        with self.timed("cone_trace"):
            image = self.cone_trace.render(gbuffer, direct, self.grid, cones=cones, gathered=gathered,
                                           emitter_irradiance=self.emitter_light.irradiance,
                                           sky_irradiance=self.sky_light.irradiance, emitters=emitters,
                                           environment=environment, cone_uniforms=pixel_cones, camera=camera,
                                           terms=s.image_terms(), ao_distance=s.ao_distance)
        voxels = dict(grid=self.grid, cones=cones, gathered=gathered, sky_irradiance=self.sky_light.irradiance,
                      emitter_irradiance=self.emitter_light.irradiance, environment=environment, cone_uniforms=pixel_cones)
        return self._blended(image, gbuffer, camera, shadow_maps, s, voxels)

    def _blended(self, image, gbuffer, camera, shadow_maps, s, voxels=None):
        """`image` with the blended surfaces over it, where the scene has any and the frame
        shows light (not AO)."""
        if not self.scene_buffers.blended_count or s.image_terms().ao:
            return image
        with self.timed("transparent"):
            return self.transparent.render(image, gbuffer, self.scene_buffers, camera, shadow_maps, s.image_terms(), voxels)

    def _shown_level(self, s):
        """The level the voxel views show; VctError where the grid has no such level."""
        if s.voxel_level >= self.grid.levels:
            raise VctError(f"must be in 0..{self.grid.levels - 1} for {self.grid.levels} voxel level(s), got {s.voxel_level}",
                           field="level")
        return s.voxel_level

    def _shadows(self, frame, camera, source):
        """Shadow maps: when the lights, the scene's bounds or its shadow casters changed, the
        tiles whose view moved or sees a caster that moved (every tile when the casters changed
        and which is not known); when the camera moved, the directional lights' cascades it
        left."""
        stage, table = self.stages["shadows"], self.table
        inputs = dict(casters=(table.structure, table.casters_changed_at), bounds=_bytes(frame.bounds), lights=frame.light_values)
        changed = stage.changed(inputs, self.track_changes)
        if changed:
            held = self._caster_bounds
            moved = None
            if held is not None and held[0] == table.structure and stage.last("casters") is not None:
                moved = table.changed_casters(stage.last("casters")[1])
            changed_casters = None  # every tile
            if self.track_changes and "casters" not in changed:
                changed_casters = []
            elif self.track_changes and moved is not None:
                changed_casters = [(lo, hi) for lo, hi in held[1][moved]] + [(lo, hi) for lo, hi in table.draw_bounds[moved]]
            with self.timed("shadow"):
                self.shadow.render(frame.lights, self.scene_buffers, frame.bounds, camera, changed_casters, source)
            if moved is None:
                self._caster_bounds = (table.structure, table.draw_bounds.copy())
            else:
                held[1][moved] = table.draw_bounds[moved]
            stage.ran(inputs)
        cascades = self.stages["cascades"]
        inputs = dict(view=_bytes(camera.centred_view_projection), shadows=stage.version)
        if self.shadow.cascaded and cascades.changed(inputs, self.track_changes):
            with self.timed("shadow"):
                redrawn = self.shadow.follow_camera(self.scene_buffers, camera)
            (cascades.ran if redrawn else cascades.extended)(inputs)
        return self.shadow.maps

    def _gbuffer(self, frame, camera, motion):
        """The G-buffer, drawn again when the view, the image size or a draw changed; with where
        each point was at the frame before where `motion` (temporal anti-aliasing)."""
        stage, table = self.stages["gbuffer"], self.table
        inputs = dict(view_projection=_bytes(camera.view_projection), size=self.size,
                      draws=(table.structure, table.draws_changed_at), motion=motion)
        if stage.changed(inputs, self.track_changes):
            with self.timed("gbuffer"):
                self.gbuffer.render(self.scene_buffers, camera,
                                    {**self.scene_buffers.motion_records(), **self.pose.resources()} if motion else None)
            stage.ran(inputs)
        return self.gbuffer.target

    def _lighting(self, gbuffer, shadow_maps, camera):
        """Direct light, again when the G-buffer (and so the viewpoint) or the shadow maps (and so
        the lights) changed."""
        stage = self.stages["lighting"]
        inputs = dict(gbuffer=self.stages["gbuffer"].version, shadows=self.stages["shadows"].version,
                      cascades=self.stages["cascades"].version)
        if stage.changed(inputs, self.track_changes):
            with self.timed("lighting"):
                self.lighting.render(gbuffer, shadow_maps, camera)
            stage.ran(inputs)
        return self.lighting.target

    def _emitters(self, frame):
        """The emissive triangles, again when an emissive draw changed."""
        stage = self.stages["emitters"]
        inputs = dict(emissive_draws=(self.table.structure, self.table.emitters_changed_at))
        if stage.changed(inputs, self.track_changes):
            with self.timed("emitters"):
                self.emitters.upload(frame_emitters(frame.emissive_draws()))
            stage.ran(inputs)
        return self.emitters

    def _environment(self, frame):
        """The environment's map, again when the environment changed."""
        stage = self.stages["environment"]
        inputs = dict(environment=frame.environment_values)
        if stage.changed(inputs, self.track_changes):
            with self.timed("environment"):
                self.environment.upload(frame.environment)
            stage.ran(inputs)
        return self.environment

    def _voxels(self, frame, s, source, emitters, environment, camera):
        """Voxelize what changed: the draws whose mesh, transform or material changed since the
        grid last took them in (as it holds them: self.held), and the levels that moved with
        the camera: scrolled where they moved by part of their cube, else voxelized anew (every
        level of a new grid); where surfaces emit, the emission volume's mip chain follows. Progressive frames (the viewer)
        move one level a frame (clipmap.scrolled_regions). The passes' arrays of values per
        record are held for the grid's records as they are after it (the emitters' and the sky's
        light where the scene has them), and the records a voxelization handed out read zero
        in them. Returns the changes.VoxelUpdate applied, or None where the voxels' inputs did
        not change."""
        stage = self.stages["voxels"]
        n, regions = frame_levels(frame, s, camera.position)
        field = "voxel_region.clipmap" if frame.clipmap is not None and s.clipmap_levels is None else "grid"
        held = self.grid.regions
        if self.progressive and self.grid.n == n and len(held) == len(regions):
            regions = scrolled_regions(held, regions)
        if self.grid.ensure(n, regions, source, field):
            stage.forget()
        if self.grid.hold_cone_emission(emitters.count > 0):  # the first emitter of a grid holding voxels
            with self.timed("voxelize"):
                self.voxelize.fill_cone_emission(self.grid)
        placed = tuple(_bytes([region.center, region.size]) for region in regions)
        table, buffers = self.table, self.scene_buffers
        held_key = (table.structure, buffers.pool.epoch)
        inputs = dict(grid=n, regions=placed, draws=(*held_key, table.draws_changed_at))
        if stage.changed(inputs, self.track_changes):
            tracked = self.track_changes and stage.inputs is not None and self.held.holds(held_key)
            moved = moved_levels(held, regions) if tracked else frozenset()
            shifts = {level: level_shift(held[level], regions[level], n) for level in moved}
            scrolled = {level: shift for level, shift in shifts.items() if shift is not None}
            if tracked:
                changed = table.changed_draws(stage.last("draws")[2])
                update = VoxelUpdate(False, self.held.held(changed), self.held.placed(table, buffers, changed),
                                     frozenset(moved - set(scrolled)), scrolled)
            else:
                changed, update = None, VoxelUpdate(True, [], [])
            if update.changed_levels(self.grid.levels):
                with self.timed("voxelize"):
                    self._clear_face_views(update, before=True)
                    self.voxelize.update(self.grid, update, buffers, table.draw_bounds)
                    self._hold_values(emitters, environment)
                    self._clear_face_views(update, before=False)
                    self.grid.zero_new_records(self.inject.base, self.gather.gathered, self.faces.reflected,
                                               self.emitter_light.irradiance, self.sky_light.irradiance, self.sky_light.traced)
                if update.scrolled:
                    self.schedule.faces_moved(update.scrolled)
            self.held.hold(held_key, table, buffers, changed)
            if emitters.count:
                with self.timed("emission_mipmap"):
                    self.voxelize.build_emission_mips(self.grid)
            stage.ran(inputs)
            return update
        return None

    def _voxel_light(self, name, work, s, update, resting, near_reach=None, **source):
        """The emitters' or the sky's light at the voxels ("emitter_light", "sky_light"), when
        the voxels, its `source` or the cones that bring it changed: where only the voxels
        changed (`update`, this frame's changes.VoxelUpdate), at the voxels of the levels it
        relit and of those that scrolled, and of the next coarser ones (cones from a level never
        read the finer ones, but a level's voxels beneath the finer level take its light).
        Progressive frames (the viewer, converging bounces) spread a relight over the
        interleave classes, one a frame, as the bounce is spread: an edit makes no frame pay
        for more than 1 voxel in K, and while an emitter or the sky keeps changing every voxel
        is still relit once every K frames; a scrolled level lights the voxels it took in at
        once and relights the others once the camera rests (`resting`: it did not move this
        frame; RadianceSchedule.light_voxels). With `near_reach` (the sky's), while draws move
        only the voxels within near_reach times their size of them are relit, the others once
        they rest too (constants.SKY_NEAR_REACH)."""
        stage = self.stages[name]
        inputs = dict(voxels=self.stages["voxels"].version, **source, cone_step=s.cone_step, cone_offset=s.cone_offset)
        changed = stage.changed(inputs, self.track_changes)
        spread = self._spreads_work(s)
        levels, scrolled, near = None, frozenset(), None
        draws_moved = update is not None and update.draws_changed
        if changed == {"voxels"} and update is not None:
            count = self.grid.levels
            levels = with_coarser_levels(update.relit_levels(count), count)
            if not draws_moved:
                scrolled = with_coarser_levels(update.scrolled, count)
            if not spread:  # converged within the frame: every voxel of a scrolled level too
                levels, scrolled = levels | scrolled, frozenset()
            elif near_reach is not None and draws_moved and not update.full:
                size = max(float(np.max(d.bounds[1] - d.bounds[0])) for d in update.removed + update.added)
                near = tuple(tuple(float(c) for c in corner) for corner in update.touched_bounds(margin=near_reach * size))
        restart = bool(changed) and levels != frozenset()
        plan = self.schedule.light_voxels(name, restart=restart, interleave=s.bounce_interleave if spread else 1,
                                          epoch=self.grid.epoch, level_count=self.grid.levels, levels=levels,
                                          scrolled=scrolled, resting=resting and not scrolled and not draws_moved, near=near)
        lit = [item for item in self._run(plan, work) if isinstance(item, schedule.LightVoxels)]
        if lit and all(item.voxels.kind == "touched" for item in lit):
            stage.extended(inputs)  # the light of before, extended to the voxels a scroll took in
        elif lit:
            stage.ran(inputs)

    def _radiance(self, s, work, update):
        """Inject direct light into the voxels when the voxels, the lights or the emitters'
        light changed (schedule.RadianceSchedule.inject); where the voxels changed by a scroll
        alone (`update`, this frame's changes.VoxelUpdate), in progressive frames, at the
        voxels it took in, gathered at once, the bounces kept
        (schedule.RadianceSchedule.scrolled)."""
        stage = self.stages["radiance"]
        inputs = dict(voxels=self.stages["voxels"].version, shadows=self.stages["shadows"].version,
                      emitter_light=self.stages["emitter_light"].version, sky_light=self.stages["sky_light"].version,
                      sky_lit=work.environment.environment is not None)
        changed = stage.changed(inputs, self.track_changes)
        if changed:
            interleave = s.bounce_interleave if self.progressive and s.bounces == 0 else 1
            spread = self._spreads_work(s) and stage.inputs is not None
            if spread and changed == {"voxels"} and update is not None and update.scrolls_only:
                self._run(self.schedule.scrolled(self.grid.epoch), work)
                stage.extended(inputs)
                return
            self._run(self.schedule.inject(voxels_changed="voxels" in changed, lights_changed=bool(changed - {"voxels"}),
                                           interleave=interleave, spread=spread, epoch=self.grid.epoch), work)
            stage.ran(inputs)

    def _spreads_work(self, s):
        """Whether per-voxel work that follows a change is spread over the interleave classes,
        one a frame: in progressive frames with converging bounces (the viewer), tracked."""
        return self.progressive and s.bounces == 0 and self.track_changes

    def _bounces(self, s, work):
        """Bounce again when the base radiance or the bounce settings changed; progressive
        frames add one bounce until the radiance settles."""
        stage = self.stages["bounces"]
        inputs = dict(radiance=self.stages["radiance"].version, bounces=s.bounces, interleave=s.bounce_interleave,
                      **s.cone_uniforms(), progressive=self.progressive)
        restart = bool(stage.changed(inputs, self.track_changes))
        if restart:
            stage.ran(inputs)
        self._run(self.schedule.bounce(restart=restart, bounces=s.bounces, interleave=s.bounce_interleave,
                                       progressive=self.progressive, epoch=self.grid.epoch, cones=s.diffuse_cones,
                                       refine_parts=schedule.refine_parts(self.grid.n, self.grid.levels)), work)

    # -- the passes' arrays of values, around a voxelization ---------------------------------

    def _hold_values(self, emitters, environment):
        """The arrays of values per record each pass owns, held for the grid's records as they
        are (made zero for new ones): the emitters' and the sky's light only where the scene
        has them, whose stages forget what they computed where the arrays are made now."""
        records = self.grid.records
        for owner in (self.inject, self.gather):
            owner.hold(records)
        self.faces.hold(self.grid)
        for name, owner, wanted in (("emitter_light", self.emitter_light, emitters.count > 0),
                                    ("sky_light", self.sky_light, environment.environment is not None)):
            if owner.hold(records, wanted):
                self.stages[name].forget()

    def _clear_face_views(self, update, before):
        """The face views zeroed where a voxelization (`update`) empties cells, by their pass:
        `before` it, the levels that scroll and, for a full one, every covered cell (the cells
        listed before it); after one of some voxels, the cells of those it touched (a scroll
        alone moves voxels whose light is composed again: its levels were zeroed before)."""
        if before:
            self.faces.hold(self.grid)
            for level in update.scrolled:
                self.faces.clear_level(self.grid, level)
            if update.full:
                self.faces.clear_covered(self.grid)
        elif not update.full and not update.scrolls_only:
            self.faces.clear_touched(self.grid)

    @current
    def render(self, scene, mode=None, **changes):
        """Render and return linear radiance, float32 (H, W, 3), row 0 at the top. `mode` and
        other settings given here apply to this frame only."""
        settings = self.settings.replace(**changes) if changes else self.settings
        if mode is not None:
            settings = settings.replace(mode=mode)
        self.render_frame(scene, settings)
        return self.radiance()

    def inputs(self, scene):
        """The files a frame of `scene` reads: the scene's own (its file, mesh files, images)
        and the GLSL files of the renderer's programs."""
        return list(scene.files) + self.programs.files()

    # -- lifetime ------------------------------------------------------------------------

    def close(self):
        if self.ctx is None:
            return
        with self.ctx:
            for render_pass in reversed(self._passes):
                render_pass.release()
            self._passes = []
            for voxels in (self.inspection, self.grid):
                if voxels is not None:
                    voxels.release()
            self.emitters.release()
            self.environment.release()
            self.scene_buffers.release()
            self.pass_timer.release()
            self.camera_block.release()
        if self._owns_context:
            self.ctx.release()
        self.ctx = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _settings(settings):
    """`settings` validated; VctError where it is not a RenderSettings."""
    if not isinstance(settings, RenderSettings):
        raise VctError(f"must be an engine.RenderSettings, got {type(settings).__name__}", field="settings")
    return settings.validate()


def _bytes(arrays):
    """Arrays as one comparable bytes key."""
    return b"".join(np.asarray(a, dtype=np.float64).tobytes() for a in arrays)
