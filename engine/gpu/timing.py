"""How long each pass of a frame takes on the GPU, measured as GPUs are measured: the pass
between the begin and end of a GL_TIME_ELAPSED query, the frame's queries read LATENCY frames
later, when the GPU has long finished them, so that timing makes no frame wait.

A software rasterizer (Mesa's llvmpipe or softpipe) runs each GL call on the CPU as it is issued
and its timer queries measure nothing (a dispatch of 160 ms reads 1 ns): there a pass is timed by
the wall clock with a finish on either side, and its figures are ready in the same frame."""
import time
from collections import deque
from contextlib import contextmanager

LATENCY = 3  # frames between a frame's queries and their reading
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "SWR")


def software_renderer(ctx):
    """Whether the context renders on the CPU (its GL calls run as they are issued)."""
    return any(name in ctx.info["GL_RENDERER"] for name in SOFTWARE_RENDERERS)


class PassTimer:
    """Milliseconds per pass name of the frames measured: `frame()` around a frame, `timed(name)`
    around each pass (a pass inside another, or on a GPU outside a frame, is not timed apart);
    `timings` holds the latest
    frame whose figures are in (LATENCY frames back on a GPU), `ready` whether it is the frame
    just rendered."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.synchronous = software_renderer(ctx)
        self.timings = {}
        self.history = []         # every frame's timings as they come in (a caller may clear it)
        self.ready = False
        self._spare = []          # queries free for use
        self._pending = deque()   # per frame measured: [(name, query)]
        self._current = None
        self._inside = False

    @contextmanager
    def frame(self):
        self._current = [] if not self.synchronous else None
        if self.synchronous:
            self.timings = {}
        try:
            yield
        finally:
            if self.synchronous:
                self.ready = True
                self.history.append(self.timings)
            else:
                self._pending.append(self._current)
                self._current = None
                self.ready = False
                while len(self._pending) > LATENCY:
                    self._read(self._pending.popleft())

    def flush(self):
        """Read every frame still pending (waits for the GPU): `timings` is the last frame's."""
        while self._pending:
            self._read(self._pending.popleft())
        self.ready = True

    @contextmanager
    def timed(self, name):
        if self._inside or (self._current is None and not self.synchronous):  # inside a pass, or outside a frame
            yield
            return
        self._inside = True
        try:
            if self.synchronous:
                self.ctx.finish()
                start = time.perf_counter()
                yield
                self.ctx.finish()
                self.timings[name] = self.timings.get(name, 0.0) + (time.perf_counter() - start) * 1000.0
            else:
                query = self._spare.pop() if self._spare else self.ctx.query(time=True)
                with query:
                    yield
                self._current.append((name, query))
        finally:
            self._inside = False

    def _read(self, measured):
        timings = {}
        for name, query in measured:
            timings[name] = timings.get(name, 0.0) + query.elapsed / 1e6
            self._spare.append(query)
        self.timings = timings
        self.history.append(timings)

    def release(self):
        self._pending.clear()  # moderngl keeps its queries to the end of the context
        self._spare = []
