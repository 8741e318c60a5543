"""Shared fixtures: one headless GL renderer per test module, the canonical scene, the
Mitsuba references, and the error figures used against them.

A test whose reference is missing (../shared/reference) skips with the reason in a user's
clone, and fails where VCT_REQUIRE_REFERENCES=1, as .ci/run sets: CI never passes silently
without the accuracy tests."""
import os
import signal
from pathlib import Path

import numpy as np
import pytest

import engine

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "scenes"
TEST_SCENES = Path(__file__).resolve().parent / "scenes"
REFERENCE = ROOT.parent / "shared" / "reference"
REQUIRE_REFERENCES = "VCT_REQUIRE_REFERENCES"

# The commands the tests run in child processes print their Python stack on a fatal signal
# (a crash in the GL driver), so a failing test's output says where the child died.
os.environ.setdefault("PYTHONFAULTHANDLER", "1")


def interruptible():
    """preexec_fn of a child process a test interrupts: SIGINT takes its default action there
    (Python's KeyboardInterrupt) even where the test run itself ignores it, as a job started in
    the background does, and its children inherit that."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def rel_mae(image, reference):
    """Relative mean absolute error: sum |c - r| / sum r."""
    return float(np.abs(image.astype(np.float64) - reference).sum() / reference.sum())


def luminance_ratio(image, reference):
    return float(image.mean() / reference.mean())


@pytest.fixture(scope="module")
def renderer():
    with engine.Renderer(256, 256) as r:
        yield r


@pytest.fixture
def cornell():
    return engine.load_scene(SCENES / "cornell_box.json")


def reference_file(path):
    """`path` if it exists; else skip the test saying why, or fail it where references are
    required (VCT_REQUIRE_REFERENCES=1)."""
    if path.exists():
        return path
    message = f"reference {path} is not available"
    if os.environ.get(REQUIRE_REFERENCES) == "1":
        pytest.fail(f"{message}, and {REQUIRE_REFERENCES}=1 requires it", pytrace=False)
    pytest.skip(message)


@pytest.fixture
def reference():
    def load(name):
        return np.load(reference_file(REFERENCE / f"cornell_box_{name}.npy")).astype(np.float64)
    return load
