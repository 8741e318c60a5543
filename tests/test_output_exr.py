"""OpenEXR output (engine.formats.output.save_exr, `vct render --hdr FILE.exr`).

Facts: an .exr holds the radiance it was given (float32 RGB, row 0 at the top), read back with
the same library; `vct render --hdr x.exr` writes one next to the PNG, the same image as
`--hdr x.npy`; any other --hdr suffix is refused before rendering, with nothing written.
"""
import numpy as np
import OpenEXR

from engine import save_exr
from test_cli import CORNELL, SMALL, assert_one_line_error, vct  # tests/ is on sys.path under pytest


def read_exr(path):
    with OpenEXR.File(str(path)) as f:
        return f.channels()["RGB"].pixels


def test_exr_round_trip_gives_back_the_radiance_exactly(tmp_path):
    """Radiance written with save_exr reads back unchanged: float32, (H, W, 3), HDR values kept."""
    radiance = np.random.default_rng(7).random((5, 7, 3)).astype(np.float32) * [1.0, 20.0, 1000.0]
    save_exr(tmp_path / "r.exr", radiance)
    back = read_exr(tmp_path / "r.exr")
    assert back.dtype == np.float32 and back.shape == (5, 7, 3)
    np.testing.assert_array_equal(back, radiance.astype(np.float32))
    assert [p.name for p in tmp_path.iterdir()] == ["r.exr"]  # no temporary file left


def test_vct_render_hdr_exr_writes_the_same_radiance_as_npy(tmp_path):
    """`--hdr x.exr` and `--hdr x.npy` hold the same linear radiance."""
    for name in ("x.exr", "x.npy"):
        result = vct("render", CORNELL, "--out", tmp_path / "x.png", "--hdr", tmp_path / name, *SMALL)
        assert result.returncode == 0, result.stderr
    np.testing.assert_array_equal(read_exr(tmp_path / "x.exr"), np.load(tmp_path / "x.npy"))


def test_vct_render_refuses_an_hdr_suffix_it_cannot_write(tmp_path):
    """`--hdr x.hdr` exits 2 with one line naming .npy and .exr, and writes nothing."""
    result = vct("render", CORNELL, "--out", tmp_path / "x.png", "--hdr", tmp_path / "x.hdr", *SMALL)
    assert_one_line_error(result, "--hdr", ".npy", ".exr")
    assert list(tmp_path.iterdir()) == []
