"""Radiance scheduling: which per-voxel work a frame does after the voxels, the lights, the
emitters or the sky changed, and the state that carries from frame to frame. GL-free: the
schedule plans work items (below) and the renderer runs each under the timer of its pass.

A bounce gathers light at every voxel with the 6 diffuse cones, traced by the anchors (1 in 4
of a surface's voxels) and interpolated by the others (passes/gather.py), and composes the face
views again with it (passes/faces.py). The gathers live in two arrays: `latest` is the one
the image and the face views use, the other keeps an earlier gather for closing the series.

- `bounces` K >= 1: K bounces when the base radiance changes; the face views carry K - 1 of
  them and the latest gather the K-th, which the image adds.
- `bounces` 0, converged within the frame (headless): bounce until the series closes (Series).
- `bounces` 0, progressive (the viewer): one interleave class of voxels (1 in K) is updated
  each frame: its anchors gather again, on top of the previous frames' gathers, its other
  voxels interpolate them, and its face views are composed again. A cycle of K frames updates
  every voxel once, and the series closes over cycles as it does over bounces. Then no bounce
  work until the next change. Where only the lights changed, the base radiance is injected
  again with the class: no frame pays for more than 1 voxel in K, and while a light keeps
  moving every voxel is still relit once every K frames.
- The gathers' cones: the set the settings name (settings.DIFFUSE_CONE_SETS), except that
  progressive frames converge with the lecture's six and, with the tiled set named, refine
  the gathers with it once that series closed (the scene rests). The voxels are sorted as one
  class for it, so that a run of the list is a region of the grid: each frame traces one run
  of the anchors (REFINE_PARTS runs at 128^3, fewer at coarser grids: refine_parts) and
  interpolates the same run of the other voxels, every voxel's face views are composed with
  the last run, and the series closes again over these cycles. At 128^3 a refining frame costs
  about what a converging one does (the tiled set is about 14 times the six's work), and the
  image changes region by region, not by interleave class (one class refined beside the
  others' old gathers draws their pattern).

The face views hold L = L_base - L_e + rho G: the light surfaces reflect (emitters light the
surfaces directly, passes/emitter_light.py). The emitters' and the sky's light at the voxels
is spread over the same classes (`ClassRounds`).

Each planning method is a generator: it yields the work items in the order they must run,
receives what a `MeasureTotals` or `ReadTotals` measured, and updates the schedule's state as
it plans. Progressive frames read nothing back in the frame that computes it: the totals at a
cycle's end are requested then and read at the start of the next frame.
"""
from dataclasses import dataclass

import numpy as np

from ..core.progress import progress
from .settings import MAX_BOUNCES

REFINE_PARTS = 96             # a 128^3 grid's anchors are refined with the tiled cones over this many frames
CONVERGENCE_TOLERANCE = 2e-3  # an increment of the totals under this fraction of them: converged
RATIO_SETTLED = 0.01          # successive increment ratios this close: close the series
NO_GAIN = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Voxels:
    """Covered voxels a work item runs over: "every" one, those of interleave class `class_index`
    ("class", of the class index last sorted) or those the last voxelization "touched"; of
    `levels` only (a frozenset; None: of every level)."""

    kind: str
    class_index: int = None
    levels: frozenset = None


EVERY_VOXEL = Voxels("every")
TOUCHED_VOXELS = Voxels("touched")


def class_voxels(class_index):
    return Voxels("class", class_index)


def _holds(every, voxels):
    """Whether selection `every`, another one than `voxels`, holds all of its voxels."""
    return every.kind == "every" and every != voxels and \
        (every.levels is None or (voxels.levels is not None and voxels.levels <= every.levels))


# -- work items: what the renderer runs, each under the timer named by its `timer` ----------

@dataclass(frozen=True)
class SortClasses:
    """Sort the covered voxels into `interleave` classes (GatherPass.sort_classes)."""
    interleave: int
    timer = "classes"


@dataclass(frozen=True)
class FindAnchors:
    """The gather's anchors of the covered voxels as they are (GatherPass.find_anchors), for
    work over the touched voxels that needs no class index."""
    timer = "classes"


@dataclass(frozen=True)
class Inject:
    """The base radiance of `voxels` (InjectPass)."""
    voxels: Voxels
    timer = "inject"


@dataclass(frozen=True)
class LightVoxels:
    """The light of `source` ("emitter_light" or "sky_light") at those of `voxels` (a class's,
    or the touched ones) that lie in `levels` (None: every level) and in the world box `box`
    ((lo, hi); None: anywhere); the others keep the light they hold."""
    source: str
    voxels: Voxels
    levels: frozenset = None
    box: tuple = None  # (lo, hi), each a tuple of 3 floats

    @property
    def timer(self):
        return self.source


@dataclass(frozen=True)
class TakeCoarserSkyLight:
    """The sky's light at those of `voxels` (the touched ones a scroll took in) that lie in
    `levels` (below the coarsest), taken from the next coarser level as it holds it at their
    surface points (SkyLightPass.take_coarser), until their own cones are traced."""
    voxels: Voxels
    levels: frozenset
    timer = "sky_light"


@dataclass(frozen=True)
class ComposeFaces:
    """Level 0 of the face views of each of `voxels` from their base radiance plus gather
    array `gathered` (None: before the first bounce)."""
    voxels: tuple
    gathered: int
    timer = "faces"


@dataclass(frozen=True)
class Mipmap:
    """The face views' coarser levels after `voxels` (a tuple of Voxels) were composed: level 1
    over the cells that hold them, the coarser levels over every covered cell of the levels
    they lie in (a grid level's mips are made of its own voxels alone)."""
    voxels: tuple
    timer = "mipmap"

    @property
    def levels(self):
        """The grid levels whose mips change: those of the voxels (None: every level)."""
        if any(voxels.levels is None for voxels in self.voxels):
            return None
        return frozenset().union(*(voxels.levels for voxels in self.voxels))


@dataclass(frozen=True)
class Gather:
    """The gather of `voxels` (a Voxels selection: a class, or the touched voxels) into gather
    array `into` through the diffuse cone set `cones` (settings.DIFFUSE_CONE_SETS): run `part`
    of `parts` equal runs of their anchors and of their other voxels (a region of the grid)."""
    voxels: Voxels
    into: int
    cones: str
    part: int = 0
    parts: int = 1
    timer = "gather"


@dataclass(frozen=True)
class ExtrapolateGather:
    """Gather array older <- latest + (latest - older) * gain (gain 0: a copy)."""
    latest: int
    older: int
    gain: tuple
    timer = "gather"


@dataclass(frozen=True)
class MeasureTotals:
    """The face views' total radiance (rgb), sent back to the plan (headless: read back now)."""
    timer = "totals"


@dataclass(frozen=True)
class RequestTotals:
    """The face views' total radiance computed on the GPU, to be read a frame later
    (ReadTotals), when it is done: progressive frames never wait for the GPU."""
    timer = "totals"


@dataclass(frozen=True)
class ReadTotals:
    """The totals the last RequestTotals computed, sent back to the plan."""
    timer = "totals"


def run_plan(plan, execute):
    """Run a plan: each item it yields through `execute(item)`, whose result (what a
    MeasureTotals or ReadTotals measured, else None) is sent back to it. Returns the items run."""
    ran, result = [], None
    while True:
        try:
            item = plan.send(result)
        except StopIteration:
            return ran
        result = execute(item)
        ran.append(item)


def refine_parts(n, levels):
    """The runs the refinement traces one a frame, for `levels` levels of n^3 voxels:
    REFINE_PARTS at 128^3 and finer, fewer at coarser grids in proportion to the voxels their
    surfaces cover (levels * n^2), so that a refining frame traces about as many anchors as one
    at 128^3 does and a coarse grid settles in as many cycles, of fewer frames."""
    return max(1, min(REFINE_PARTS, round(REFINE_PARTS * levels * n * n / 128 ** 2)))


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
            return tuple(float(g) for g in r / (1.0 - r))
        return None


class ClassRounds:
    """Work over the covered voxels spread over their interleave classes, one class a frame (the
    viewer), or all of them at once (interleave 1). A restart queues every class, starting
    where the last round stopped, so work restarted every frame still reaches every class
    once every K frames. A round covers the voxels of some levels (None: every level); one
    restarted before it finished also covers the levels of the one it replaces. `deferred`:
    levels whose voxels a round is to cover once the camera and the draws rest (they scrolled,
    or a round covered a box of them). A round covers a world box of those levels' voxels
    (None: all of them); one restarted before it finished, the box holding both."""

    def __init__(self):
        self.interleave = 1
        self.pending = []    # the classes still to do since the last restart
        self.phase = 0       # the class to do first after the next restart
        self.levels = None   # the levels whose voxels the round covers
        self.box = None      # the world box (lo, hi) of the voxels it covers
        self.deferred = frozenset()

    def restart(self, interleave, levels=None, box=None):
        if levels is None and box is None:
            self.deferred = frozenset()
        if self.pending:
            if levels is not None:
                levels = None if self.levels is None else levels | self.levels
            if box is not None:
                box = None if self.box is None else (tuple(map(min, box[0], self.box[0])), tuple(map(max, box[1], self.box[1])))
        self.interleave, self.levels, self.box = interleave, levels, box
        self.phase %= interleave
        self.pending = [(self.phase + k) % interleave for k in range(interleave)]

    def next_class(self):
        """The class to do this frame, or None once every class is done."""
        if not self.pending:
            return None
        chosen = self.pending.pop(0)
        self.phase = (chosen + 1) % self.interleave
        return chosen


class RadianceSchedule:
    """The state of the voxels' radiance between frames, and the plans that move it on.

    `settled`: no bounce work is due (always, outside progressive frames, once a plan ran).
    Progressive frames are in one of three states: converging with the six cones (`settled`
    False: each frame one class, `phase` the next), refining with the tiled ones (`refining`:
    each frame one run of the voxels, `part` the next) or settled. Also carried: the classes
    whose base radiance is still to inject (`pending_base`, for interleave `pending_for`), the
    voxel sets injected since the face views were last composed (`stale_faces`), the epoch of
    the covered list the base radiance was last injected for and the class index was sorted
    for, the series of cycle totals, and whether the running cycle ran on the current base
    radiance throughout."""

    def __init__(self):
        self.latest = 0
        self.settled = True
        self.series = None    # progressive: the totals at the end of each cycle
        self.phase = 0        # progressive: the interleave class updated next
        self.cones = "six"    # the diffuse cone set the converged gathers use (settings.DIFFUSE_CONE_SETS)
        self.refining = False  # progressive: the gathers are refined with the tiled cones
        self.part = 0          # progressive, refining: the run of the voxels refined next
        self.parts = REFINE_PARTS  # progressive, refining: the runs of a cycle (refine_parts)
        self.iterations = 0   # bounces the last restart ran (or the progressive bounces so far)
        self.pending_base = set()
        self.pending_for = 1
        self.stale_faces = []
        self.injected_epoch = None
        self.sorted_for = None  # (epoch, interleave) of the class index as last sorted
        self.cycle_clean = False
        self.totals_requested = False  # progressive: a cycle's totals wait to be read
        self.voxel_light_rounds = {"emitter_light": ClassRounds(), "sky_light": ClassRounds()}

    # -- plans -------------------------------------------------------------------------------

    @property
    def idle(self):
        """No work is due: the bounces settled, and no round of the voxels' light runs or
        waits for the camera to rest."""
        return self.settled and not any(rounds.pending or rounds.deferred for rounds in self.voxel_light_rounds.values())

    def light_voxels(self, source, *, restart, interleave, epoch, level_count, levels=None, scrolled=frozenset(),
                     resting=True, near=None):
        """The light of `source` at the voxels of a grid of `level_count` levels, when its inputs
        changed (`restart`: spread over `interleave` classes, over the voxels of `levels`, None:
        every level; where `near` is a world box, over the voxels inside it, the others of those
        levels once the camera and the draws rest), and for the classes still due. Where levels
        scrolled (`scrolled`), the voxels they took in (the touched ones) are lit at once: the
        sky's light below the coarsest level as the next coarser level holds it
        (TakeCoarserSkyLight), its own cones being traced once the camera rests. Their other
        voxels keep the light they had until the camera rests (`resting`: it did not move this
        frame, and no level scrolled), from when they are lit again over the classes. Its cones
        read the face views' coverage, so a restart composes them first, with the gathers so
        far (the light they hold follows with the bounces), and a scroll the ones it moved,
        unless the other source's plan did."""
        rounds = self.voxel_light_rounds[source]
        if scrolled:
            rounds.deferred |= scrolled
        elif rounds.deferred and resting and not restart:
            restart, levels, near, rounds.deferred = True, rounds.deferred, None, frozenset()
        if restart:
            if near is not None:
                rounds.deferred |= levels
            rounds.restart(interleave, levels, near)
            yield from self._sort(epoch, rounds.interleave)
            yield from self._compose([EVERY_VOXEL], self.latest)
        elif scrolled and self.stale_faces:
            yield from self._compose(self.stale_faces, self.latest)
        if scrolled:
            yield FindAnchors()
            if source == "sky_light":
                coarsest = level_count - 1
                if coarsest > 0:
                    yield TakeCoarserSkyLight(TOUCHED_VOXELS, frozenset(range(coarsest)))
                yield LightVoxels(source, TOUCHED_VOXELS, frozenset({coarsest}))
            else:
                yield LightVoxels(source, TOUCHED_VOXELS)
        chosen = rounds.next_class()
        if chosen is not None:
            yield from self._sort(epoch, rounds.interleave)
            yield LightVoxels(source, class_voxels(chosen), rounds.levels, rounds.box)

    def inject(self, *, voxels_changed, lights_changed, interleave, spread, epoch):
        """The base radiance after the voxels or the light reaching them changed. Spread
        (progressive frames with converging bounces, tracked): the voxels a voxelization
        touched now (every voxel, if the list changed more than once since the last
        injection), and where the light changed each class as the bounce next updates it.
        Otherwise every voxel, now."""
        if not spread:
            yield from self._inject_every(interleave, epoch)
            return
        if voxels_changed:
            if epoch.follows(self.injected_epoch):
                yield from self._inject_now(TOUCHED_VOXELS, epoch)
            else:
                yield from self._inject_every(interleave, epoch)
        if lights_changed:
            self.pending_base, self.pending_for = set(range(interleave)), interleave
            self.cycle_clean = False

    def scrolled(self, epoch):
        """The base radiance and the gather of the voxels a scroll took in (the touched ones),
        the others keeping theirs (the scene and its light did not change, only which part of
        it a level holds): the touched voxels (which lie in the levels `epoch` scrolled)
        injected, gathered and composed now, with the face views of every voxel of those levels,
        which the scroll moved (unless the voxels' light composed them this frame), and their
        levels' mips. No bounce restarts: the scrolled levels' light is made again once the
        camera rests (light_voxels)."""
        touched = Voxels("touched", levels=epoch.scrolled_levels)
        yield FindAnchors()
        yield from self._inject_now(touched, epoch)
        yield Gather(touched, self.latest, "six")
        yield from self._compose(self.stale_faces, self.latest)

    def faces_moved(self, levels):
        """A scroll of `levels` zeroed their face views where voxels left: every voxel's of
        those levels are composed again before cones next read them."""
        self.stale_faces.append(Voxels("every", levels=frozenset(levels)))

    def bounce(self, *, restart, bounces, interleave, progressive, epoch, cones, refine_parts=REFINE_PARTS):
        """The bounces through the diffuse cone set `cones`: all of them when `restart` (the
        base radiance or the bounce settings changed), outside progressive frames; in
        progressive frames this frame's share, the tiled set's refinement in `refine_parts`
        runs."""
        if restart:
            self.iterations = 0
            self.totals_requested = False
            self.cones, self.refining, self.part, self.parts = cones, False, 0, refine_parts
            if bounces == 0 and progressive:  # resume from the previous gathers; a new series from the next cycle
                self.settled, self.series = False, None
            else:
                self.settled = True
                yield from self._compose([EVERY_VOXEL], None)
                if bounces:
                    yield from self._fixed(bounces, epoch)
                else:
                    yield from self._converge(epoch)
        if not self.settled:
            yield from self._advance(interleave, epoch)

    # -- steps -------------------------------------------------------------------------------

    def _sort(self, epoch, interleave):
        """Sort the classes unless the class index is sorted so for the covered list as it is."""
        if self.sorted_for != (epoch, interleave):  # epochs compare by identity
            self.sorted_for = (epoch, interleave)
            yield SortClasses(interleave)

    def _inject_every(self, interleave, epoch):
        yield from self._sort(epoch, interleave)
        yield from self._inject_now(EVERY_VOXEL, epoch)
        self.pending_base = set()

    def _inject_now(self, voxels, epoch):
        yield Inject(voxels)
        self.injected_epoch = epoch
        self.stale_faces.append(voxels)
        self.cycle_clean = False

    def _compose(self, voxels, gathered):
        """The face views of `voxels` (a list of Voxels; a selection of every voxel of some
        levels holds the others of those levels), then every mip level of their levels: none
        is stale after."""
        voxels = tuple(dict.fromkeys(voxels))
        voxels = tuple(v for v in voxels if not any(_holds(every, v) for every in voxels))
        yield ComposeFaces(voxels, gathered)
        yield Mipmap(voxels)
        self.stale_faces = []

    def _gather_every(self, epoch):
        yield from self._sort(epoch, 1)
        yield Gather(class_voxels(0), self.latest, self.cones)

    def _fixed(self, bounces, epoch):
        for k in range(1, bounces + 1):
            yield from self._gather_every(epoch)
            if k < bounces:
                yield from self._compose([EVERY_VOXEL], self.latest)
        self.iterations = bounces

    def _converge(self, epoch):
        series = Series((yield MeasureTotals()))
        # How many bounces the series takes to close is not known ahead (a handful; at most
        # MAX_BOUNCES): a count and a rate on a terminal, no bar; no line in a log.
        with progress(None, "bounces", "bounce", summary=False) as bouncing:
            for iteration in range(1, MAX_BOUNCES + 1):
                self.latest = 1 - self.latest  # the other array holds the previous gather
                yield from self._gather_every(epoch)
                yield from self._compose([EVERY_VOXEL], self.latest)
                self.iterations = iteration
                bouncing.update()
                outcome = series.add((yield MeasureTotals()))
                if outcome is Series.CONVERGED:
                    return
                if outcome is not None:
                    yield from self._close_series(outcome)
                    return

    def _close_series(self, gain):
        """latest <- latest + (latest - earlier) * gain; the face views follow."""
        yield ExtrapolateGather(self.latest, 1 - self.latest, gain)
        self.latest = 1 - self.latest
        yield from self._compose([EVERY_VOXEL], self.latest)

    def _advance(self, interleave, epoch):
        """Progressive: the next interleave class gathers again (its anchors' cones read the
        face views of the frames before), with its base radiance injected first if the lights
        changed since, and its face views are composed again (while refining: _refine). Where
        the voxels changed, the face views of the voxels injected since (and of the class) are
        composed before the gather instead, with every mip level, as its cones must see the
        voxels as they are now. At the end of a cycle that ran on the current base radiance
        throughout, the series is checked and the gathers kept: the series starts from gathers
        that all read it, as a bounce's do, since the totals it watches miss light that only
        moved."""
        if self.totals_requested:
            self.totals_requested = False
            yield from self._end_cycle((yield ReadTotals()))
            if self.settled:
                return
        if self.refining:
            yield from self._refine(epoch)
            return
        if self.pending_base and self.pending_for != interleave:  # classes of another interleave: all again
            self.pending_base, self.pending_for = set(range(interleave)), interleave
        yield from self._sort(epoch, interleave)
        self.phase %= interleave
        chosen = self.phase
        if chosen in self.pending_base:
            yield Inject(class_voxels(chosen))
            self.pending_base.discard(chosen)
        stale = self.stale_faces
        if stale:
            yield from self._compose(stale + [class_voxels(chosen)], self.latest)
        yield Gather(class_voxels(chosen), self.latest, "six")
        if not stale:
            yield from self._compose([class_voxels(chosen)], self.latest)
        self.phase = (chosen + 1) % interleave
        self.iterations += 1
        if self.phase == 0:
            if self.cycle_clean:
                yield RequestTotals()
                self.totals_requested = True
            self.cycle_clean = not self.pending_base

    def _refine(self, epoch):
        """Refining: the next run of the voxels (sorted as one class) gathers with the tiled
        cones, after composing the face views of the voxels injected since; every voxel's face
        views are composed with the last run, which ends a cycle. It waits while a round of the
        emitters' or the sky's light runs over the interleave classes, sorted otherwise."""
        if any(rounds.pending for rounds in self.voxel_light_rounds.values()):
            return
        yield from self._sort(epoch, 1)
        if self.stale_faces:
            yield from self._compose(self.stale_faces, self.latest)
        yield Gather(class_voxels(0), self.latest, "tiled", self.part, self.parts)
        self.part = (self.part + 1) % self.parts
        self.iterations += 1
        if self.part == 0:
            yield from self._compose([EVERY_VOXEL], self.latest)
            if self.cycle_clean:
                yield RequestTotals()
                self.totals_requested = True
            self.cycle_clean = True

    def _end_cycle(self, total):
        """Check the series with a cycle's totals; unless it closes, keep the gathers of that
        cycle's end (still the latest) for closing it. Once the six cones' series closes with
        the tiled set named, the refinement starts a series of its own."""
        outcome = None if self.series is None else self.series.add(total)
        if self.series is None:
            self.series = Series(total)
        if outcome is not None:
            if outcome is not Series.CONVERGED:
                yield from self._close_series(outcome)
            if self.cones == "tiled" and not self.refining:
                self.refining, self.part, self.series = True, 0, None
                return
            self.settled, self.refining = True, False
            return
        yield ExtrapolateGather(self.latest, 1 - self.latest, NO_GAIN)
