"""Bounce scheduling: how the voxel radiance gets its diffuse bounces after its base radiance
(emission + direct light) changed, and the state that carries from frame to frame.

A bounce gathers light at every voxel with the 6 diffuse cones (passes/gather.py) and composes
the face views again with it, L = L_base + k_d G (passes/faces.py). The gathers live in two
volumes: `latest` is the one the image and the face views use.

- `bounces` K >= 1: K bounces when the base radiance changes; the face views carry K - 1 of
  them and the latest gather the K-th, which the image adds.
- `bounces` 0, converged within the frame (headless): bounce until the grid's total radiance
  T_k settles; once its increments shrink by a steady ratio r, add the rest of the geometric
  series, r / (1 - r) times the last increment, to the gathers in one step.
- `bounces` 0, progressive (the viewer): one bounce per frame on top of the previous frame's,
  re-gathering one interleave class of voxels (1 in K) each frame, until the totals stop
  changing over a whole cycle of classes; then no bounce work until the next change.
"""
import numpy as np

from .settings import MAX_BOUNCES

CONVERGENCE_TOLERANCE = 2e-3  # relative change of the totals under which bouncing stops
RATIO_SETTLED = 0.01          # successive increment ratios this close: close the series


class BounceSchedule:
    def __init__(self, gather, faces):
        self.gather = gather
        self.faces = faces
        self.latest = 0
        self.settled = True
        self.phase = 0        # progressive: the interleave class that gathers next
        self.totals = []      # progressive: the grid's total radiance after each bounce
        self.iterations = 0   # bounces the last restart ran (or the progressive bounces so far)

    def gathered(self, grid):
        return grid.gathered[self.latest]

    def restart(self, grid, settings, cone_uniforms, progressive, timed):
        """The base radiance or the bounce settings changed."""
        self.totals = []
        self.iterations = 0
        if settings.bounces == 0 and progressive:  # resume from the previous gathers, from this frame on
            self.settled = False
            return
        self.settled = True
        self._compose(grid, None, timed)
        if settings.bounces:
            self._fixed(grid, settings.bounces, cone_uniforms, timed)
        else:
            self._converge(grid, cone_uniforms, timed)

    def advance(self, grid, settings, cone_uniforms, timed):
        """Progressive: one bounce for this frame. The face views are composed from the base
        radiance and the gathers so far (the cones must see the current base radiance); then,
        unless the totals stopped changing over a whole cycle of classes, the next interleave
        class gathers again (the image reads the gathers directly)."""
        if self.settled:
            return
        interleave = settings.bounce_interleave
        self._compose(grid, self.gathered(grid), timed)
        self.totals.append(self.faces.totals(grid))
        recent = np.array(self.totals[-(interleave + 1):])
        if len(recent) == interleave + 1 and np.all(np.abs(np.diff(recent, axis=0)) <= CONVERGENCE_TOLERANCE * recent[-1]):
            self.settled = True
            return
        self.gather.sort_classes(grid, interleave)
        self.phase %= interleave
        with timed("gather"):
            self.gather.run(grid, cone_uniforms, self.gathered(grid), grid.class_segments[self.phase])
        self.phase += 1
        self.iterations += 1

    def _compose(self, grid, gathered, timed):
        with timed("faces"):
            self.faces.compose(grid, gathered)
        with timed("mipmap"):
            self.faces.mipmap(grid)

    def _gather_all(self, grid, cone_uniforms, out, timed):
        self.gather.sort_classes(grid, 1)
        with timed("gather"):
            self.gather.run(grid, cone_uniforms, grid.gathered[out], grid.class_segments[0])

    def _fixed(self, grid, bounces, cone_uniforms, timed):
        for k in range(1, bounces + 1):
            self.latest = k % 2
            self._gather_all(grid, cone_uniforms, self.latest, timed)
            if k < bounces:
                self._compose(grid, self.gathered(grid), timed)
        self.iterations = bounces

    def _converge(self, grid, cone_uniforms, timed):
        totals = [self.faces.totals(grid)]
        ratios = []
        older, newer = 0, 1
        for iteration in range(1, MAX_BOUNCES + 1):
            self._gather_all(grid, cone_uniforms, newer, timed)
            self.latest = newer
            self._compose(grid, self.gathered(grid), timed)
            self.iterations = iteration
            totals.append(self.faces.totals(grid))
            increment = totals[-1] - totals[-2]
            if np.all(increment <= CONVERGENCE_TOLERANCE * totals[-1]):
                return
            if len(totals) >= 3:
                previous = totals[-2] - totals[-3]
                ratios.append(np.where(previous > 0, increment / np.maximum(previous, 1e-30), 0.0))
            if len(ratios) >= 2 and np.all(np.abs(ratios[-1] - ratios[-2]) <= RATIO_SETTLED) and np.all(ratios[-1] < 1):
                r = np.clip(ratios[-1], 0.0, 0.99)
                with timed("gather"):
                    self.gather.extrapolate(grid, grid.gathered[newer], grid.gathered[older], r / (1.0 - r))
                self.latest = older
                self._compose(grid, self.gathered(grid), timed)
                return
            older, newer = newer, older
