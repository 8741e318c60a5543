"""Figures for the overlay: frame rate and frame time, process CPU and memory, and what a
frame drew and what it reused."""
import time
from collections import deque

import psutil

PROCESS_SAMPLE_SECONDS = 0.5
# What a frame can take from an earlier one: (name, the pass that makes it).
REUSABLE = (("G-buffer", "gbuffer"), ("shadow maps", "shadow"), ("direct light", "lighting"), ("voxels", "voxelize"))


def reused(passes_ran):
    """What the frame that ran `passes_ran` (Renderer.passes_ran) took from earlier frames:
    the names of REUSABLE whose pass it skipped, of those its image needs (a G-buffer view
    needs no shadows or light; only a cone trace or voxel view needs voxels)."""
    ran = set(passes_ran)
    needed = {"G-buffer"}
    if "gbuffer_view" not in ran:
        needed |= {"shadow maps", "direct light"}
    if ran & {"cone_trace", "voxel_view"}:
        needed.add("voxels")
    return [name for name, made_by in REUSABLE if name in needed and made_by not in ran]


def work_line(passes_ran, draw_calls):
    """The overlay's line on a frame's work, e.g. "7 draw calls; reused shadow maps, voxels"."""
    parts = [f"{draw_calls} draw calls"] if draw_calls else []
    kept = reused(passes_ran)
    if kept:
        parts.append("reused " + ", ".join(kept))
    return "; ".join(parts) or "no draw calls; nothing reused"


class FrameStats:
    """Frames per second and milliseconds per frame, averaged over the last `window` seconds
    (at least the last frame). Each `tick()` marks the end of a frame, measured wall clock."""

    def __init__(self, window=1.0, clock=time.perf_counter):
        self.window = window
        self.clock = clock
        self._last = None
        self._durations = deque()  # seconds per frame, newest last
        self._host = deque()       # seconds the host spent issuing each of those frames' work
        self.frames = 0

    def host(self, seconds):
        """The host's seconds of the frame about to end: the renderer's call that issues its work."""
        self._host.append(seconds)

    def tick(self):
        now = self.clock()
        if self._last is not None:
            self._durations.append(now - self._last)
            while len(self._durations) > 1 and sum(self._durations) - self._durations[0] >= self.window:
                self._durations.popleft()
        while len(self._host) > max(len(self._durations), 1):
            self._host.popleft()
        self._last = now
        self.frames += 1
        return now

    @property
    def ms_per_frame(self):
        if not self._durations:
            return 0.0
        return 1000.0 * sum(self._durations) / len(self._durations)

    @property
    def host_ms(self):
        """The host's milliseconds a frame over the same frames."""
        return 1000.0 * sum(self._host) / len(self._host) if self._host else 0.0

    @property
    def fps(self):
        ms = self.ms_per_frame
        return 1000.0 / ms if ms > 0 else 0.0


class ProcessStats:
    """This process's CPU use (percent of one core, so above 100 with threads) and resident
    memory in MB, sampled at most every PROCESS_SAMPLE_SECONDS (psutil)."""

    def __init__(self, clock=time.perf_counter):
        self.process = psutil.Process()
        self.clock = clock
        self.process.cpu_percent(None)  # starts the interval; the first reading comes later
        self._sampled = clock()
        self.cpu_percent = None  # None until the first interval has passed
        self.ram_mb = self.process.memory_info().rss / 2 ** 20

    def update(self):
        now = self.clock()
        if now - self._sampled >= PROCESS_SAMPLE_SECONDS:
            self.cpu_percent = self.process.cpu_percent(None)
            self.ram_mb = self.process.memory_info().rss / 2 ** 20
            self._sampled = now
