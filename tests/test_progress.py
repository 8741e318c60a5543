"""engine/core/progress.py: the progress of long work, on stderr.

Facts: on a terminal long work shows a bar with the units done of the total, the rate and the
time left, cleared when the work ends; in a log (stderr not a terminal) it prints nothing while
it runs and one summary line at the end, with no carriage-return bar (tools/reference.py's
passes among such work); work shorter than MIN_SECONDS, and steps inside a command's work
(summary=False), print nothing in a log; work that an exception ends prints no summary line;
set_quiet(True) shows nothing at all, nor does a process whose stderr is closed.
"""
import fcntl
import inspect
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pytest

from engine.core.progress import MIN_SECONDS, progress, set_quiet, summary_line

ROOT = Path(__file__).resolve().parent.parent
LONG = MIN_SECONDS * 1.3  # seconds of work: long enough for a bar and a summary line
SUMMARY = re.compile(r"^work: 6 steps in \d+\.\d s \(\d+\.\d step/s\)$")


def work(total, seconds, summary=True):
    """`total` steps of work over `seconds`."""
    with progress(total, "work", "step", summary=summary) as steps:
        for _ in range(total):
            time.sleep(seconds / total)
            steps.update()


# The start of the programs run on a terminal: work() and what it needs.
WORK = "import time\nfrom engine.core.progress import progress, set_quiet\n\n" + inspect.getsource(work)


def on_a_terminal(code):
    """What `code` (run after WORK in a new Python) writes to a pseudo-terminal 100 columns
    wide, its stdout and stderr both, with the terminal's \\r\\n line ends as \\n."""
    master, terminal = pty.openpty()
    fcntl.ioctl(terminal, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # tqdm draws nothing 0 columns wide
    process = subprocess.Popen([sys.executable, "-c", WORK + code], cwd=ROOT, stdout=terminal, stderr=terminal)
    os.close(terminal)
    output = b""
    while select.select([master], [], [], 60)[0]:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # EIO: the process exited, the terminal is closed
            break
        if not chunk:
            break
        output += chunk
    os.close(master)
    assert process.wait(timeout=60) == 0, output
    return output.decode().replace("\r\n", "\n")


@pytest.fixture
def log(capsys):
    """stderr captured: not a terminal. Returns a function giving what was written to it since."""
    yield lambda: capsys.readouterr().err
    set_quiet(False)


def test_on_a_terminal_long_work_shows_a_bar_with_count_rate_and_time_left_cleared_at_the_end():
    output = on_a_terminal(f"work(6, {LONG})")
    frames = output.split("\r")
    assert any(re.fullmatch(r"work: +\d+%\|.*\| [1-6]/6 \[00:0\d<00:0\d, +\d+\.\d+step/s\]", f) for f in frames), output
    assert frames[-1].strip() == "", output  # cleared: the terminal keeps what the command reports
    assert "steps in" not in output


def test_on_a_terminal_short_work_shows_nothing():
    assert on_a_terminal("work(100, 0.1)") == ""


def test_in_a_log_long_work_prints_one_summary_line_at_the_end(log):
    work(6, LONG)
    lines = log().splitlines()
    assert len(lines) == 1 and SUMMARY.match(lines[0]), lines


def test_in_a_log_short_work_and_steps_print_nothing(log):
    work(6, 0.1)
    work(6, LONG, summary=False)  # a step of a command's work: loading a mesh file, the bounces
    assert log() == ""


def test_work_that_an_exception_ends_prints_no_summary_line(log):
    with pytest.raises(KeyboardInterrupt):
        with progress(6, "work", "step") as steps:
            time.sleep(LONG)
            steps.update()
            raise KeyboardInterrupt
    assert log() == ""


def test_on_a_terminal_an_interrupted_bar_is_cleared():
    output = on_a_terminal(f"""
try:
    with progress(6, "work", "step") as steps:
        for _ in range(3):
            time.sleep({LONG} / 3)
            steps.update()
        raise KeyboardInterrupt
except KeyboardInterrupt:
    print("interrupted")
""")
    assert "3/6" in output and output.split("\r")[-1] == "interrupted\n", output


def test_quiet_shows_nothing_on_a_terminal_or_in_a_log(log):
    assert on_a_terminal(f"set_quiet(True)\nwork(6, {LONG})") == ""
    set_quiet(True)
    work(6, LONG)
    assert log() == ""


def test_with_stderr_closed_long_work_runs_and_stdout_keeps_only_its_own():
    """A process started with stderr closed (`2>&-`: sys.stderr is None) shows nothing."""
    result = subprocess.run([sys.executable, "-c", WORK + f"work(6, {LONG})\nprint('done')"], cwd=ROOT,
                            stdout=subprocess.PIPE, text=True, timeout=60, preexec_fn=lambda: os.close(2))
    assert result.returncode == 0 and result.stdout == "done\n", result.stdout


def test_a_summary_line_says_count_time_and_rate():
    assert summary_line("render", 12, "frame", 3.43) == "render: 12 frames in 3.4 s (3.5 frame/s)"
    assert summary_line("reference", 4, "pass", 16.8) == "reference: 4 passes in 16.8 s (4.2 s/pass)"
    assert summary_line("load", 1, "mesh", 2.0) == "load: 1 mesh in 2.0 s (2.0 s/mesh)"


def test_a_reference_render_in_a_log_prints_at_most_its_summary_line_and_no_bar(tmp_path):
    """tools/reference.py's passes (64 of them, a couple of seconds here) through a pipe: no
    carriage-return bar, and the one summary line where they took at least MIN_SECONDS; with
    --quiet nothing."""
    pytest.importorskip("mitsuba")
    scene = tmp_path / "scene.json"
    scene.write_text('{"camera": {"position": [0.5, 0.5, 1], "look_at": [0.5, 0.5, 0], "vertical_fov_deg": 53},'
                     ' "materials": {"m": {}}, "lights": [{"type": "point", "position": [0.5, 0.5, 0.5], "intensity": [1, 1, 1]}],'
                     ' "objects": [{"name": "Quad", "type": "quad", "material": "m",'
                     ' "vertices": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]}]}')
    command = [sys.executable, str(ROOT / "tools" / "reference.py"), str(scene), str(tmp_path / "out.npy"),
               "--spp", "128", "--pass-spp", "2", "--max-depth", "2", "--width", "100", "--height", "100"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "\r" not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) <= 1 and all(re.fullmatch(r"reference: 64 passes in \d+\.\d s \(.*\)", line) for line in lines), lines
    quiet = subprocess.run(command + ["--quiet"], capture_output=True, text=True, timeout=300)
    assert quiet.returncode == 0 and quiet.stderr == "", quiet.stderr
