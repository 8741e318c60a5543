"""Shared fixtures: one headless GL renderer per test module, the canonical scene, the
Mitsuba references, and the error figures used against them."""
from pathlib import Path

import numpy as np
import pytest

import engine

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "scenes"
TEST_SCENES = Path(__file__).resolve().parent / "scenes"
REFERENCE = ROOT.parent / "shared" / "reference"


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


@pytest.fixture
def reference():
    def load(name):
        path = REFERENCE / f"cornell_box_{name}.npy"
        if not path.exists():
            pytest.skip(f"reference {path} is not available")
        return np.load(path).astype(np.float64)
    return load
