"""Anti-aliasing of headless renders: each pixel the mean of jittered samples over its area.

Facts: at the default sample count the Cornell box's direct light matches the path tracer's
box-filtered pixels within relMAE 0.0015 (the pixel centres alone read 0.0037, nearly all of
it on the edges); one sample is the pixel centres' image; the voxels and their light are
computed once for all the samples, the screen passes once per sample; `vct render` takes the
default count and `--samples`.
"""
import numpy as np

import engine
from engine.frame.settings import HEADLESS_SAMPLES
from test_cli import assert_one_line_error, vct  # tests/ is on sys.path under pytest

from conftest import SCENES, rel_mae

SCREEN_PASSES = ("gbuffer", "lighting", "cone_trace", "average_samples")


def test_the_default_samples_box_filter_the_pixels_as_the_path_tracer_does(cornell, reference):
    expected = reference("direct")
    with engine.Renderer(256, 256) as r:
        centres = r.render(cornell, mode="direct", samples=1)
        filtered = r.render(cornell, mode="direct", samples=HEADLESS_SAMPLES)
    assert rel_mae(centres, expected) > 0.003
    assert rel_mae(filtered, expected) <= 0.0015


def test_one_sample_is_the_image_through_the_pixel_centres(cornell):
    with engine.Renderer(96, 96) as r:
        default = r.render(cornell, grid=32)
        one = r.render(cornell, grid=32, samples=1)
        several = r.render(cornell, grid=32, samples=4)
    assert np.array_equal(default, one)
    assert not np.array_equal(one, several)


def test_the_voxels_are_computed_once_and_the_screen_passes_once_per_sample(cornell):
    def passes(samples):
        with engine.Renderer(96, 96) as r:
            r.render(cornell, grid=32, samples=samples)
            return r.passes_ran

    one, four = passes(1), passes(4)
    voxel_passes = [p for p in one if p not in SCREEN_PASSES]
    assert voxel_passes and [p for p in four if p not in SCREEN_PASSES] == voxel_passes
    for name in ("gbuffer", "lighting", "cone_trace"):
        assert four.count(name) == 4 * one.count(name) == 4
    assert four.count("average_samples") == 4


def test_vct_render_anti_aliases_by_default_and_takes_samples(tmp_path):
    scene = SCENES / "cornell_box.json"
    small = ("--width", "64", "--height", "64", "--grid", "32")
    for name, extra in (("default", ()), ("one", ("--samples", "1"))):
        result = vct("render", scene, *small, *extra, "--out", tmp_path / f"{name}.png", "--hdr", tmp_path / f"{name}.npy")
        assert result.returncode == 0, result.stderr
    with engine.Renderer(64, 64) as r:
        loaded = engine.load_scene(scene)
        expected = {name: r.render(loaded, grid=32, samples=samples) for name, samples in (("default", HEADLESS_SAMPLES), ("one", 1))}
    for name in expected:
        assert rel_mae(np.load(tmp_path / f"{name}.npy"), expected[name]) < 1e-4
    assert_one_line_error(vct("render", scene, "--samples", "0", "--out", tmp_path / "x.png"), "--samples")
    assert not (tmp_path / "x.png").exists()
