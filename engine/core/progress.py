"""Progress of long work (the frames of a sequence, the passes of a reference, the nodes of a
large mesh file, the bounces of a converged render), on stderr: stdout carries what a command
reports (`wrote ...`).

    with progress(len(frames), "render", "frame") as rendering:
        for frame in frames:
            ...
            rendering.update()

- On a terminal (stderr is a tty): a tqdm bar with the units done of the total, the rate and
  the time left. It appears once the work has run MIN_SECONDS, so short work never flashes
  one, and it is cleared when the work ends: the terminal keeps what the command reports.
  Work inside other work (a mesh file loaded while a sequence renders) gets its bar below.
- Otherwise (a log, a pipe): nothing while the work runs, and one line when it ends,
  `render: 12 frames in 3.4 s (3.5 frame/s)`, where it ran at least MIN_SECONDS: a line about
  a second's work tells a log nothing the command's own report does not. Steps inside the
  work a command was run for (loading a mesh file, bouncing the light to convergence) pass
  summary=False and print no line, so a log gets one line for the work, not one per step.
- Work that an exception (KeyboardInterrupt among them) ends: its bar is closed, no line.
- set_quiet(True) (the CLI's and the tools' --quiet): nothing at all, for every piece of work
  in the process, deep ones included (mesh loading), without a flag passed down to them.
"""
import contextlib
import sys
import time

from tqdm import tqdm

MIN_SECONDS = 1.0  # work shorter than this shows no bar and prints no line

_quiet = False


def set_quiet(quiet):
    """Show no progress at all (True), or show it (False, the default), process-wide."""
    global _quiet
    _quiet = bool(quiet)


class Progress:
    """The units of work done so far; the bar on a terminal (None elsewhere) follows them."""

    def __init__(self, bar):
        self.bar = bar
        self.done = 0

    def update(self, n=1):
        """`n` more units done."""
        self.done += n
        if self.bar is not None:
            self.bar.update(n)


@contextlib.contextmanager
def progress(total, description, unit, summary=True):
    """A Progress of `total` units (None where the count is not known ahead: no bar, no time
    left, the count and the rate), named `description`, each unit a `unit` ("frame"). Ending
    with fewer than `total` done is fine (work that converges early). `summary`: print the one
    line at the end where stderr is not a terminal (the module docstring)."""
    shown = not _quiet and sys.stderr is not None  # None: the process was started with stderr closed
    terminal = shown and sys.stderr.isatty()
    bar = None
    if terminal:
        bar = tqdm(total=total, desc=description, unit=unit, file=sys.stderr, delay=MIN_SECONDS, leave=False)
    work = Progress(bar)
    start = time.perf_counter()
    try:
        yield work
    finally:
        if bar is not None:
            bar.close()
    seconds = time.perf_counter() - start
    if summary and shown and not terminal and seconds >= MIN_SECONDS and work.done:
        with contextlib.suppress(OSError):  # a closed or full stderr loses only this line
            print(summary_line(description, work.done, unit, seconds), file=sys.stderr, flush=True)


def print_above(text):
    """Write `text` (a whole line) on stderr above the progress bars, which stay below it
    (nothing where the process has no stderr)."""
    if sys.stderr is not None:
        tqdm.write(text, file=sys.stderr, end="")


def summary_line(description, done, unit, seconds):
    """`render: 12 frames in 3.4 s (3.5 frame/s)`; slower than a unit a second, `(4.2 s/pass)`."""
    rate = f"{done / seconds:.1f} {unit}/s" if done >= seconds else f"{seconds / done:.1f} s/{unit}"
    return f"{description}: {done} {_plural(unit, done)} in {seconds:.1f} s ({rate})"


def _plural(unit, count):
    if count == 1:
        return unit
    return unit + ("es" if unit.endswith(("s", "sh", "ch", "x")) else "s")
