"""GLSL hot reload for the viewer: poll the renderer for changed shader files.

A program whose file (or an included glsl/lib file) changed is rebuilt, and the next frame
recomputes everything with it (Renderer.reload_shaders); on a compile error,
or a file that is missing or unreadable, the last good program keeps running and the error,
with the real file and line (`glsl/lib/brdf.glsl:12: error: ...`, `glsl/lighting/shade_lights.frag:5:
error: #include "lib/brdf.glsl": no such file`), is kept here for the window and printed to
stderr once per change. Fixing the file clears it. Works the same without a window (tests).
"""
import sys
import time

POLL_SECONDS = 0.25


class ShaderWatcher:
    def __init__(self, renderer, interval=POLL_SECONDS, clock=time.perf_counter, stream=None):
        self.renderer = renderer
        self.interval = interval
        self.clock = clock
        self.stream = stream  # None: sys.stderr at the time of printing
        self._polled = clock()
        self.errors = []  # current error messages, one string per distinct error (may be multi-line)
        self.rebuilt = 0  # programs rebuilt by the last poll that rebuilt any

    def poll(self, force=False):
        """Rebuild changed programs if the interval has passed (or `force`). Returns the
        current error messages."""
        now = self.clock()
        if not force and now - self._polled < self.interval:
            return self.errors
        self._polled = now
        rebuilt, _ = self.renderer.reload_shaders()
        if rebuilt:
            self.rebuilt = rebuilt
        self._update(_messages(self.renderer.programs.errors()), rebuilt)
        return self.errors

    def _update(self, messages, rebuilt):
        out = self.stream or sys.stderr
        if messages == self.errors:
            if rebuilt:
                print(f"vct view: reloaded {_programs(rebuilt)}", file=out)
            return
        if messages:
            print("vct view: shader error (the last good program keeps running):", file=out)
            for message in messages:
                print(message, file=out)
        else:
            print(f"vct view: shader errors fixed, reloaded {_programs(rebuilt)}", file=out)
        out.flush()
        self.errors = messages


def _programs(count):
    return f"{count} program{'s' if count != 1 else ''}"


def _messages(errors):
    """Distinct messages, in a stable order (one file can break several programs)."""
    out = []
    for error in errors:
        text = "\n".join(getattr(error, "lines", None) or [str(error)])
        if text not in out:
            out.append(text)
    return sorted(out)
