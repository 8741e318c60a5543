"""Bounce scheduling: how the voxel radiance gets its diffuse bounces after its base radiance
(emission + direct light) changed, and the state that carries from frame to frame.

A bounce gathers light at every voxel with the 6 diffuse cones, traced by the anchors (1 in 4
of a surface's voxels) and interpolated by the others (passes/gather.py), and composes the face
views again with it (passes/faces.py). The gathers live in two
volumes: `latest` is the one the image and the face views use, the other keeps an earlier
gather for closing the series.

- `bounces` K >= 1: K bounces when the base radiance changes; the face views carry K - 1 of
  them and the latest gather the K-th, which the image adds.
- `bounces` 0, converged within the frame (headless): bounce until the series closes (Series).
- `bounces` 0, progressive (the viewer): one interleave class of voxels (1 in K) is updated
  each frame: its anchors gather again, on top of the previous frames' gathers, its other
  voxels interpolate them, and its face views are composed again. A cycle of K frames updates
  every voxel once, and the series closes over cycles as it does over bounces. Then no bounce
  work until the next change. Where only the lights changed, the base radiance is injected
  again with the class (`inject`): no frame pays for more than 1 voxel in K, and while a light
  keeps moving every voxel is still relit once every K frames.

The face views hold L = L_base - L_e + rho G: the light surfaces reflect (emitters light the
surfaces directly, passes/emitter_light.py). `ClassRounds` spreads other per-voxel work over
the same classes (the emitters' light at the voxels).
"""
import numpy as np

from .progress import progress
from .settings import MAX_BOUNCES

CONVERGENCE_TOLERANCE = 2e-3  # an increment of the totals under this fraction of them: converged
RATIO_SETTLED = 0.01          # successive increment ratios this close: close the series


class Series:
    """The grid's total radiance T_k after each bounce (or cycle of bounces). The bounces are a
    geometric series: once an increment D_k = T_k - T_(k-1) is negligible it has converged;
    once the increments shrink by a steady ratio r, the remaining bounces add r / (1 - r) times
    the last increment, which `add` returns as the gain to apply (per colour channel)."""

    CONVERGED = "converged"

    def __init__(self, total):
        self.totals = [total]
        self.ratios = []

    def add(self, total):
        """Series.CONVERGED, a gain (close the series with it), or None (bounce on)."""
        self.totals.append(total)
        increment = self.totals[-1] - self.totals[-2]
        if np.all(increment <= CONVERGENCE_TOLERANCE * self.totals[-1]):
            return Series.CONVERGED
        if len(self.totals) >= 3:
            previous = self.totals[-2] - self.totals[-3]
            self.ratios.append(np.where(previous > 0, increment / np.maximum(previous, 1e-30), 0.0))
        if len(self.ratios) >= 2 and np.all(np.abs(self.ratios[-1] - self.ratios[-2]) <= RATIO_SETTLED) \
                and np.all(self.ratios[-1] < 1):
            r = np.clip(self.ratios[-1], 0.0, 0.99)
            return r / (1.0 - r)
        return None


class ClassRounds:
    """Work over the covered voxels spread over their interleave classes, one class a frame (the
    viewer), or all of them at once (interleave 1). A restart queues every class, starting
    where the last round stopped, so work restarted every frame still reaches every class
    once every K frames."""

    def __init__(self):
        self.interleave = 1
        self.pending = []  # the classes still to do since the last restart
        self.phase = 0     # the class to do first after the next restart

    def restart(self, interleave):
        self.interleave = interleave
        self.phase %= interleave
        self.pending = [(self.phase + k) % interleave for k in range(interleave)]

    def next_class(self):
        """The class to do this frame, or None once every class is done."""
        if not self.pending:
            return None
        chosen = self.pending.pop(0)
        self.phase = (chosen + 1) % self.interleave
        return chosen


class BounceSchedule:
    def __init__(self, injection, gather, faces):
        self.injection = injection
        self.gather = gather
        self.faces = faces
        self.latest = 0
        self.settled = True
        self.series = None    # progressive: the totals at the end of each cycle
        self.phase = 0        # progressive: the interleave class updated next
        self.iterations = 0   # bounces the last restart ran (or the progressive bounces so far)
        self.pending_base = set()  # progressive: the classes whose base radiance is still to inject,
        self.pending_for = 1       # of this interleave
        self.stale_faces = []      # progressive: VoxelSegments to compose before the next gather
        self.injected_epoch = None  # the covered list's epoch the base radiance was last injected for
        self.classes = None         # the ClassIndex of the covered voxels, as last sorted (sort_classes)
        self.cycle_clean = False   # progressive: this cycle runs on the current base radiance throughout

    def gathered(self, grid):
        return grid.gathered[self.latest]

    @staticmethod
    def interleave(settings, progressive):
        """The classes the covered voxels are sorted into: the progressive bounce's, else one."""
        return settings.bounce_interleave if progressive and settings.bounces == 0 else 1

    def inject(self, grid, shadow_maps, interleave, timed):
        """The base radiance of every voxel, now."""
        classes = self.sort_classes(grid, interleave, timed)
        self._inject_now(grid, shadow_maps, classes.segment(), timed)
        self.pending_base = set()

    def inject_touched(self, grid, shadow_maps, interleave, timed):
        """Progressive, the voxels changed: the base radiance of the voxels the voxelization
        touched, now (of every voxel, if others changed since the last injection)."""
        if not grid.epoch.follows(self.injected_epoch):
            self.inject(grid, shadow_maps, interleave, timed)
        else:
            self._inject_now(grid, shadow_maps, grid.touched.segment(), timed)

    def inject_spread(self, interleave):
        """Progressive, the lights changed: the base radiance of each class when it is next
        updated (advance)."""
        self.pending_base, self.pending_for = set(range(interleave)), interleave
        self.cycle_clean = False

    def _inject_now(self, grid, shadow_maps, segment, timed):
        with timed("inject"):
            self.injection.run(grid, shadow_maps, segment)
        self.injected_epoch = grid.epoch
        self.stale_faces.append(segment)
        self.cycle_clean = False

    def restart(self, grid, settings, cone_uniforms, progressive, timed):
        """The base radiance or the bounce settings changed."""
        self.iterations = 0
        if settings.bounces == 0 and progressive:  # resume from the previous gathers; a new series from the next cycle
            self.settled, self.series = False, None
            return
        self.settled = True
        self.compose(grid, None, timed)
        if settings.bounces:
            self._fixed(grid, settings.bounces, cone_uniforms, timed)
        else:
            self._converge(grid, cone_uniforms, timed)

    def advance(self, grid, settings, cone_uniforms, shadow_maps, timed):
        """Progressive: this frame's share of the bounces. The next interleave class gathers
        again (its anchors' cones read the face views of the frames before), with its base
        radiance injected first if the lights changed since, and its face views are composed
        again. Where the voxels changed, the face views of the voxels injected since (and of
        the class) are composed before the gather instead, with every mip level, as its cones
        must see the voxels as they are now. At the end of a cycle that ran on the current base
        radiance throughout, the series is checked and the gathers kept: the series starts from
        gathers that all read it, as a bounce's do, since the totals it watches miss light that
        only moved."""
        if self.settled:
            return
        interleave = settings.bounce_interleave
        if self.pending_base and self.pending_for != interleave:  # classes of another interleave: all again
            self.pending_base, self.pending_for = set(range(interleave)), interleave
        classes = self.sort_classes(grid, interleave, timed)
        self.phase %= interleave
        chosen = self.phase
        if chosen in self.pending_base:
            with timed("inject"):
                self.injection.run(grid, shadow_maps, classes.segment(chosen))
            self.pending_base.discard(chosen)
        stale = self.stale_faces
        if stale:
            every_voxel = classes.segment()
            extra = [] if every_voxel in stale else [classes.segment(chosen)]
            self._compose_segments(grid, self.gathered(grid), stale + extra, timed)
        with timed("gather"):
            self.gather.run(grid, cone_uniforms, self.gathered(grid), classes, chosen)
        if not stale:
            self.compose(grid, self.gathered(grid), timed, chosen)
        self.phase = (chosen + 1) % interleave
        self.iterations += 1
        if self.phase == 0:
            if self.cycle_clean:
                self._end_cycle(grid, timed)
            self.cycle_clean = not self.pending_base

    def _end_cycle(self, grid, timed):
        """Check the series; unless it closes, keep the gathers of this cycle's end for closing it."""
        total = self.faces.totals(grid)
        outcome = None if self.series is None else self.series.add(total)
        if self.series is None:
            self.series = Series(total)
        if outcome is not None:
            if outcome is not Series.CONVERGED:
                self._close_series(grid, outcome, timed)
            self.settled = True
            return
        with timed("gather"):
            self.gather.copy(grid, self.gathered(grid), grid.gathered[1 - self.latest])

    def sort_classes(self, grid, interleave, timed):
        """The ClassIndex of the grid's voxels in `interleave` classes, sorted again unless it
        is sorted so for the covered list as it is."""
        if self.classes is None or not self.classes.sorted_for(grid.epoch, interleave):
            with timed("classes"):
                self.classes = self.gather.sort_classes(grid, interleave)
        return self.classes

    def compose(self, grid, gathered, timed, class_index=None):
        """The face views of the voxels of interleave class `class_index` (None: every voxel)
        from their base radiance and `gathered` (None: before the first bounce), then the mip
        levels over the cells they changed."""
        if class_index is None:
            self._compose_segments(grid, gathered, [self.classes.segment()], timed)
            return
        with timed("faces"):
            self.faces.compose(grid, gathered, self.classes.segment(class_index))
        with timed("mipmap"):
            self.faces.mipmap(grid, self.classes, class_index)

    def _compose_segments(self, grid, gathered, segments, timed):
        """The face views of the voxels of `segments`, then every mip level: none is stale after."""
        with timed("faces"):
            for segment in segments:
                self.faces.compose(grid, gathered, segment)
        with timed("mipmap"):
            self.faces.mipmap(grid)
        self.stale_faces = []

    def _close_series(self, grid, gain, timed):
        """latest <- latest + (latest - earlier) * gain; the face views follow."""
        with timed("gather"):
            self.gather.extrapolate(grid, self.gathered(grid), grid.gathered[1 - self.latest], gain)
        self.latest = 1 - self.latest
        self.compose(grid, self.gathered(grid), timed)

    def _gather_all(self, grid, cone_uniforms, timed):
        classes = self.sort_classes(grid, 1, timed)
        with timed("gather"):
            self.gather.run(grid, cone_uniforms, self.gathered(grid), classes, 0)

    def _fixed(self, grid, bounces, cone_uniforms, timed):
        for k in range(1, bounces + 1):
            self._gather_all(grid, cone_uniforms, timed)
            if k < bounces:
                self.compose(grid, self.gathered(grid), timed)
        self.iterations = bounces

    def _converge(self, grid, cone_uniforms, timed):
        series = Series(self.faces.totals(grid))
        # How many bounces the series takes to close is not known ahead (a handful; at most
        # MAX_BOUNCES): a count and a rate on a terminal, no bar; no line in a log.
        with progress(None, "bounces", "bounce", summary=False) as bouncing:
            for iteration in range(1, MAX_BOUNCES + 1):
                self.latest = 1 - self.latest  # the other volume holds the previous gather
                self._gather_all(grid, cone_uniforms, timed)
                self.compose(grid, self.gathered(grid), timed)
                self.iterations = iteration
                bouncing.update()
                outcome = series.add(self.faces.totals(grid))
                if outcome is Series.CONVERGED:
                    return
                if outcome is not None:
                    self._close_series(grid, outcome, timed)
                    return
