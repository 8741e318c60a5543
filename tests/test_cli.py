"""The `vct` command line (engine.app.cli), run as a real process (`python -m engine.app.cli`), or in
this process (engine.app.cli.main) where a failure of the driver is simulated or many cases run.

Facts: every command's --help is complete; `vct render` writes the PNG and the float32 HDR it
was asked for and says where; every bad input (a broken scene, an impossible setting, an
unwritable output, a shader that does not compile) exits with code 2 and exactly one stderr
line "vct: error: ..." naming the file and/or field, with no traceback and no output file
(nor temporary file) left behind.
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from test_scene_file import BAD_SCENES, write_bad_scene  # tests/ is on sys.path under pytest

ROOT = Path(__file__).resolve().parent.parent
CORNELL = ROOT / "scenes" / "cornell_box.json"
SMALL = ["--mode", "direct", "--width", "32", "--height", "32"]

SETTINGS_OPTIONS = ["--width", "--height", "--mode", "--grid", "--bounces", "--mip", "--cone-step", "--cone-offset",
                    "--ao-distance", "--no-direct", "--no-diffuse", "--no-specular", "--exposure", "--shaders", "--tonemap",
                    "--camera", "--environment"]
HELP = {
    (): ["render", "view", "bench"],
    ("render",): ["scene", "--out", "--hdr", *SETTINGS_OPTIONS],
    ("view",): ["scene", "--frames", "--screenshot", "--no-panels", *SETTINGS_OPTIONS],
    ("bench",): ["scene", "--frames", "--warmup", "--grids", "--json", "--reference", *SETTINGS_OPTIONS],
}


def vct(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "engine.app.cli", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def assert_one_line_error(result, *mentions):
    """Exit code 2, no traceback, exactly one stderr line "vct: error: ..." holding each mention."""
    assert result.returncode == 2, (result.returncode, result.stderr)
    assert "Traceback" not in result.stderr + result.stdout, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("vct: error: "), lines[0]
    for mention in mentions:
        assert str(mention) in lines[0], (mention, lines[0])
    return lines[0]


@pytest.fixture
def out_dir(tmp_path):
    """An empty output directory; each test below checks what is left in it."""
    directory = tmp_path / "out"
    directory.mkdir()
    return directory


# ---- help ------------------------------------------------------------------------------------

def test_entry_point_is_the_cli_main():
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+

    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts["vct"] == "engine.app.cli:main"


@pytest.mark.parametrize("command, options", list(HELP.items()), ids=lambda v: " ".join(v) if isinstance(v, tuple) else None)
def test_help_exits_0_and_mentions_every_option(command, options):
    result = vct(*command, "--help")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert result.stdout.startswith("usage: vct" + "".join(f" {c}" for c in command))
    for option in options:
        assert option in result.stdout, f"`vct {' '.join(command)} --help` does not mention {option}"


@pytest.mark.parametrize("command, bounds", [
    ("render", ["--bounces", "at most 64"]),
    ("view", ["--frames", "at most 10000", "--bounces", "at most 64"]),
    ("bench", ["--frames", "at most 1000", "--warmup", "grid sizes, each at most once"]),
])
def test_help_states_the_upper_bound_of_every_count(command, bounds):
    """Every loop a command line controls is bounded, and --help says how far."""
    text = " ".join(vct(command, "--help").stdout.split())
    for bound in bounds:
        assert bound in text, bound


@pytest.mark.parametrize("args, option", [
    (["view", CORNELL, "--frames", "10001"], "--frames"),
    (["bench", CORNELL, "--frames", "1001"], "--frames"),
    (["bench", CORNELL, "--warmup", "1001"], "--warmup"),
    (["bench", CORNELL, "--grids", "16,16"], "--grids"),
], ids=lambda v: " ".join(map(str, v[2:])) if isinstance(v, list) else None)
def test_counts_beyond_their_bound_exit_2_naming_the_option(args, option):
    assert_one_line_error(vct(*args), option)


def test_render_help_lists_every_mode_and_tone_mapper():
    from engine.frame.settings import MODES, TONEMAPS

    text = vct("render", "--help").stdout
    for name in (*MODES, *TONEMAPS):
        assert name in text


# ---- a good render ---------------------------------------------------------------------------

def test_render_writes_a_32x32_rgb_png_and_float32_hdr_and_prints_the_output_path(out_dir):
    png, npy = out_dir / "cornell.png", out_dir / "cornell.npy"
    result = vct("render", CORNELL, "--out", png, "--hdr", npy, *SMALL)
    assert result.returncode == 0, result.stderr
    assert str(png) in result.stdout and str(npy) in result.stdout
    assert "Traceback" not in result.stderr
    with Image.open(png) as image:
        assert image.format == "PNG" and image.mode == "RGB" and image.size == (32, 32)
    radiance = np.load(npy)
    assert radiance.dtype == np.float32 and radiance.shape == (32, 32, 3)
    assert np.all(np.isfinite(radiance)) and radiance.min() >= 0 and radiance.max() > 0
    assert sorted(p.name for p in out_dir.iterdir()) == ["cornell.npy", "cornell.png"]  # no temporary files


def test_render_size_defaults_to_the_scene_camera(tmp_path, out_dir):
    import json

    data = json.loads(CORNELL.read_text())
    data["camera"].update(width=24, height=16)
    scene = tmp_path / "small.json"
    scene.write_text(json.dumps(data))
    result = vct("render", scene, "--out", out_dir / "small.png", "--mode", "albedo")
    assert result.returncode == 0, result.stderr
    with Image.open(out_dir / "small.png") as image:
        assert image.size == (24, 16)


# ---- bad input: exit 2, one line, nothing written --------------------------------------------

@pytest.mark.parametrize("case", BAD_SCENES, ids=lambda case: case.id)
def test_bad_scene_exits_2_with_one_line_naming_the_file_and_field_and_writes_nothing(tmp_path, out_dir, case):
    scene = write_bad_scene(tmp_path, case)
    result = vct("render", scene, "--out", out_dir / "x.png", "--hdr", out_dir / "x.npy", *SMALL)
    assert_one_line_error(result, scene, case.field or "", case.mention)
    assert list(out_dir.iterdir()) == []


def test_missing_scene_file_exits_2_naming_it(out_dir):
    result = vct("render", out_dir / "nowhere.json", "--out", out_dir / "x.png", *SMALL)
    assert_one_line_error(result, out_dir / "nowhere.json")
    assert list(out_dir.iterdir()) == []


@pytest.mark.parametrize("args, field", [
    (["--grid", "48"], "grid"), (["--grid", "512"], "grid"), (["--grid", "8"], "grid"),
    (["--width", "0"], "--width"), (["--height", "-3"], "--height"), (["--width", "wide"], "--width"),
    (["--exposure", "nan"], "--exposure"), (["--exposure", "0"], "exposure"), (["--exposure", "1e30"], "exposure"),
    (["--mip", "9", "--grid", "16"], "mip"), (["--bounces", "-1"], "--bounces"),
    (["--bounces", "100000"], "bounces"), (["--bounces", "65"], "bounces"),
    (["--mode", "raytraced"], "--mode"), (["--tonemap", "filmic"], "--tonemap"),
], ids=lambda v: " ".join(v) if isinstance(v, list) else None)
def test_impossible_setting_exits_2_with_one_line_naming_the_option(out_dir, args, field):
    result = vct("render", CORNELL, "--out", out_dir / "x.png", "--hdr", out_dir / "x.npy", *SMALL, *args)
    assert_one_line_error(result, field)
    assert list(out_dir.iterdir()) == []


def test_usage_error_exits_2_without_traceback():
    result = vct("render", CORNELL, "--mode", "raytraced")  # argparse: --out missing, bad mode
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert vct().returncode == 2  # no command


@pytest.mark.parametrize("flag", ["--out", "--hdr"])
def test_output_in_a_missing_directory_exits_2_naming_path_and_flag(out_dir, flag):
    paths = {"--out": out_dir / "x.png", "--hdr": out_dir / "x.npy"}
    paths[flag] = out_dir / "no" / "such" / "dir" / paths[flag].name
    result = vct("render", CORNELL, "--out", paths["--out"], "--hdr", paths["--hdr"], *SMALL)
    assert_one_line_error(result, paths[flag], flag)
    assert list(out_dir.iterdir()) == []


@pytest.mark.parametrize("flag", ["--out", "--hdr"])
def test_output_that_is_a_directory_exits_2_naming_path_and_flag(out_dir, flag):
    taken = out_dir / "taken"
    taken.mkdir()
    paths = {"--out": out_dir / "x.png", "--hdr": out_dir / "x.npy", flag: taken}
    result = vct("render", CORNELL, "--out", paths["--out"], "--hdr", paths["--hdr"], *SMALL)
    assert_one_line_error(result, taken, flag)
    assert [p.name for p in out_dir.iterdir()] == ["taken"] and list(taken.iterdir()) == []


@pytest.mark.parametrize("flag", ["--out", "--hdr"])
def test_output_that_is_a_device_exits_2_and_leaves_the_device_alone(out_dir, flag):
    """/dev/null is writable, but replacing it with a file would break the system."""
    paths = {"--out": out_dir / "x.png", "--hdr": out_dir / "x.npy", flag: "/dev/null"}
    result = vct("render", CORNELL, "--out", paths["--out"], "--hdr", paths["--hdr"], *SMALL)
    assert_one_line_error(result, "/dev/null", flag, "not a regular file")
    assert Path("/dev/null").is_char_device() and list(out_dir.iterdir()) == []


@pytest.mark.parametrize("name", ["x.npy", "x.exr", "x.jpg", "x"])
def test_out_that_is_not_a_png_exits_2_naming_the_flag_and_writes_nothing(out_dir, name):
    """--out is the tone-mapped PNG; linear radiance goes to --hdr, so `--out x.npy` is a mistake
    to report, not PNG bytes to write under an .npy name."""
    result = vct("render", CORNELL, "--out", out_dir / name, *SMALL)
    assert_one_line_error(result, name, "--out", ".png", "--hdr")
    assert list(out_dir.iterdir()) == []


def test_hdr_and_png_on_the_same_path_exits_2(out_dir):
    result = vct("render", CORNELL, "--out", out_dir / "x.png", "--hdr", out_dir / "x.png", *SMALL)
    assert_one_line_error(result, "--hdr")
    assert list(out_dir.iterdir()) == []


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc, a directory not even root can create files in")
def test_png_that_fails_to_write_after_rendering_leaves_no_hdr_behind(out_dir):
    """/proc passes the up-front check for root but refuses the file: the failure comes after
    the render, and the .npy must not be written either."""
    result = vct("render", CORNELL, "--out", "/proc/vct-test.png", "--hdr", out_dir / "x.npy", *SMALL)
    assert_one_line_error(result, "/proc/vct-test.png")
    assert list(out_dir.iterdir()) == []


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc, a directory not even root can create files in")
def test_png_that_fails_to_write_after_rendering_leaves_the_existing_hdr_file_as_it_was(out_dir):
    """A failed render never deletes nor changes a file that was there before."""
    hdr = out_dir / "k.npy"
    hdr.write_bytes(b"the previous render")
    result = vct("render", CORNELL, "--out", "/proc/vct-test.png", "--hdr", hdr, *SMALL)
    assert_one_line_error(result, "/proc/vct-test.png")
    assert hdr.read_bytes() == b"the previous render"
    assert list(out_dir.iterdir()) == [hdr]


def test_output_name_too_long_for_the_file_system_exits_2_and_leaves_the_existing_hdr_file_as_it_was(out_dir):
    hdr = out_dir / "k.npy"
    hdr.write_bytes(b"the previous render")
    png = out_dir / ("x" * 300 + ".png")
    result = vct("render", CORNELL, "--out", png, "--hdr", hdr, *SMALL)
    assert_one_line_error(result, "--out", "too long")
    assert hdr.read_bytes() == b"the previous render"
    assert list(out_dir.iterdir()) == [hdr]


def test_concurrent_renders_to_the_same_outputs_all_succeed_and_leave_both_files(out_dir):
    """Four processes writing the same --out and --hdr at once each write their own temporary
    files and move them into place: every one succeeds, and both files are there, complete."""
    png, npy = out_dir / "same.png", out_dir / "same.npy"
    command = [sys.executable, "-m", "engine.app.cli", "render", str(CORNELL), "--out", str(png), "--hdr", str(npy), *SMALL]
    processes = [subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for _ in range(4)]
    results = [process.communicate(timeout=120) + (process.returncode,) for process in processes]
    assert [code for _, _, code in results] == [0, 0, 0, 0], [err for _, err, _ in results]
    assert np.load(npy).shape == (32, 32, 3)
    with Image.open(png) as image:
        assert image.size == (32, 32)
    assert sorted(p.name for p in out_dir.iterdir()) == ["same.npy", "same.png"]


# ---- writing outputs (engine.formats.output.write_files) ---------------------------------------------

def test_write_files_writes_all_or_nothing_and_keeps_the_files_that_were_there(tmp_path):
    """The second output cannot be written (its directory is missing): the first file keeps its
    old content and no temporary file is left."""
    from engine.core.errors import VctError
    from engine.formats.output import write_files

    first = tmp_path / "first.npy"
    first.write_bytes(b"old")
    with pytest.raises(VctError, match="second.png"):
        write_files([(first, lambda f: f.write(b"new")), (tmp_path / "missing" / "second.png", lambda f: f.write(b"new"))])
    assert first.read_bytes() == b"old"
    assert list(tmp_path.iterdir()) == [first]


def test_write_files_removes_its_temporaries_whatever_a_writer_raises(tmp_path):
    from engine.formats.output import write_files

    def broken(f):
        f.write(b"half")
        raise ValueError("encoder failed")

    target = tmp_path / "x.png"
    target.write_bytes(b"old")
    with pytest.raises(ValueError):
        write_files([(target, broken)])
    assert target.read_bytes() == b"old"
    assert list(tmp_path.iterdir()) == [target]


def test_write_files_to_the_same_path_at_the_same_time_both_succeed(tmp_path):
    """Another writer of the same path finishes while this one is writing: each has its own
    temporary file, so neither fails nor removes the other's result; the last move wins."""
    from engine.formats.output import write_files

    target = tmp_path / "same.npy"

    def slow(f):
        write_files([(target, lambda g: g.write(b"fast"))])
        f.write(b"slow")

    write_files([(target, slow)])
    assert target.read_bytes() == b"slow"
    assert list(tmp_path.iterdir()) == [target]


def test_write_files_takes_names_as_long_as_the_file_system_allows(tmp_path):
    """Temporary names do not grow with the target's name."""
    from engine.formats.output import write_files

    longest = tmp_path / ("x" * 255)
    write_files([(longest, lambda f: f.write(b"data"))])
    assert longest.read_bytes() == b"data"
    assert list(tmp_path.iterdir()) == [longest]


def test_shaders_directory_that_does_not_exist_exits_2_naming_it(out_dir):
    result = vct("render", CORNELL, "--out", out_dir / "x.png", "--shaders", out_dir / "glsl", *SMALL)
    assert_one_line_error(result, "--shaders", out_dir / "glsl")
    assert list(out_dir.iterdir()) == []


def test_shader_syntax_error_exits_2_naming_the_glsl_file_and_line_and_writes_nothing(tmp_path, out_dir):
    glsl = tmp_path / "glsl"
    shutil.copytree(ROOT / "glsl", glsl)
    brdf = glsl / "lib" / "brdf.glsl"
    lines = brdf.read_text().splitlines()
    body = next(i for i, line in enumerate(lines) if line.rstrip().endswith("{"))  # first function
    lines.insert(body + 1, "    float broken = ;")
    brdf.write_text("\n".join(lines) + "\n")
    result = vct("render", CORNELL, "--out", out_dir / "x.png", "--hdr", out_dir / "x.npy", "--shaders", glsl, *SMALL)
    assert_one_line_error(result, f"glsl/lib/brdf.glsl:{body + 2}:")
    assert list(out_dir.iterdir()) == []


def test_no_opengl_45_exits_2_with_one_line(out_dir):
    """A context backend that cannot give OpenGL 4.5 is one clear line, not a traceback."""
    env = dict(os.environ, VCT_GL_BACKEND="none-such")
    result = subprocess.run([sys.executable, "-m", "engine.app.cli", "render", str(CORNELL), "--out", str(out_dir / "x.png"), *SMALL],
                            cwd=ROOT, capture_output=True, text=True, timeout=120, env=env)
    assert_one_line_error(result, "OpenGL 4.5")
    assert list(out_dir.iterdir()) == []


def test_osmesa_fallback_renders_the_same_image(out_dir):
    """Where EGL is missing, OSMesa gives the same OpenGL 4.5 pipeline."""
    from ctypes.util import find_library
    if not find_library("OSMesa"):
        pytest.skip("libOSMesa is not installed (Debian: libosmesa6)")
    outputs = {}
    for backend in ("egl", "osmesa"):
        env = dict(os.environ, VCT_GL_BACKEND=backend)
        npy = out_dir / f"{backend}.npy"
        result = subprocess.run([sys.executable, "-m", "engine.app.cli", "render", str(CORNELL), "--out", str(out_dir / f"{backend}.png"),
                                 "--hdr", str(npy), *SMALL], cwd=ROOT, capture_output=True, text=True, timeout=120, env=env)
        assert result.returncode == 0, result.stderr
        outputs[backend] = np.load(npy)
    assert np.abs(outputs["egl"] - outputs["osmesa"]).max() < 1e-4


def test_image_larger_than_the_driver_allows_exits_2(out_dir):
    result = vct("render", CORNELL, "--out", out_dir / "x.png", "--mode", "direct", "--width", "100000", "--height", "16")
    assert_one_line_error(result, "size")
    assert list(out_dir.iterdir()) == []


# ---- hostile inputs: one line, exit 2, nothing written ---------------------------------------

def run_main(capsys, *args):
    """`vct ARGS` in this process: (exit code, stdout, stderr lines)."""
    from engine.app.cli import main

    try:
        code = main([str(a) for a in args])
    except SystemExit as exit:  # argparse
        code = exit.code
    out, err = capsys.readouterr()
    return code, out, err.splitlines()


def test_scene_path_that_is_a_device_exits_2_without_reading_it(out_dir):
    result = vct("render", "/dev/zero", "--out", out_dir / "x.png", *SMALL)
    assert_one_line_error(result, "/dev/zero", "not a regular file")
    assert list(out_dir.iterdir()) == []


def _reference_files(directory):
    """Reference files `bench --reference` must refuse, by name."""
    good = np.ones((32, 32, 3), np.float32)
    files = {"npz-archive.npz": lambda p: np.savez(p, radiance=good),
             "object-array.npy": lambda p: np.save(p, np.array([{"radiance": 1}], dtype=object), allow_pickle=True),
             "wrong-shape.npy": lambda p: np.save(p, good[:16]),
             "nan.npy": lambda p: np.save(p, np.where(np.eye(32)[..., None] > 0, np.nan, good)),
             "all-black.npy": lambda p: np.save(p, 0 * good),
             "text.npy": lambda p: p.write_text("not an array")}
    for name, write in files.items():
        write(directory / name)
    return sorted(directory / name for name in files)


def test_bench_reference_that_is_not_a_matching_radiance_array_exits_2_naming_it(tmp_path, capsys):
    """An .npz archive ended in AttributeError; every unusable reference is one line."""
    for reference in _reference_files(tmp_path):
        code, out, err = run_main(capsys, "bench", CORNELL, "--reference", reference, "--frames", 1, "--warmup", 0,
                                  "--grids", 16, *SMALL)
        assert code == 2 and len(err) == 1, (reference.name, err)
        assert err[0].startswith(f"vct: error: {reference}: --reference: "), err[0]


def test_bench_warns_where_the_radiance_does_not_settle_before_the_timed_frames(capsys, monkeypatch):
    """`vct bench` lets the bounces settle before it times a kind of frame; where they have not
    within its frame allowance, the frames it times carry their work, and it says so in one
    line naming the kinds."""
    import engine.app.bench
    monkeypatch.setattr(engine.app.bench, "SETTLE_FRAMES", 2)
    code, out, err = run_main(capsys, "bench", CORNELL, "--frames", 1, "--warmup", 0, "--grids", 16, "--width", 32, "--height", 32)
    assert code == 0
    assert len(err) == 1 and err[0].startswith("vct: warning: cornell_box: ") and "did not settle within 2 frames" in err[0], err
    assert all(kind in err[0] for kind in ("static", "camera", "light", "object")), err


def test_bench_reference_npz_exits_2_without_traceback_end_to_end(tmp_path):
    reference = tmp_path / "reference.npz"
    np.savez(reference, radiance=np.ones((32, 32, 3), np.float32))
    result = vct("bench", CORNELL, "--reference", reference, "--frames", 1, "--warmup", 0, "--grids", 16, *SMALL)
    assert_one_line_error(result, reference, "--reference")


def test_render_targets_the_driver_cannot_create_exit_2_naming_the_size(out_dir, capsys, monkeypatch):
    """A size under the driver's limit that it still cannot allocate (llvmpipe: 16384x16384
    fails with 'the framebuffer is not complete') is a size error, not a traceback."""
    import moderngl

    from engine.passes import target

    def failing_target(self, size):
        raise moderngl.Error("the framebuffer is not complete (INCOMPLETE_ATTACHMENT)")

    monkeypatch.setattr(target.ScreenTarget, "resize", failing_target)
    code, out, err = run_main(capsys, "render", CORNELL, "--out", out_dir / "x.png", "--mode", "direct",
                              "--width", 16384, "--height", 16384)
    assert code == 2 and len(err) == 1, err
    assert err[0].startswith("vct: error: size: cannot create the 16384x16384 render targets"), err[0]
    assert list(out_dir.iterdir()) == []


def test_radiance_with_nan_or_infinity_is_never_written(tmp_path, out_dir):
    """A lighting shader that overflows float32: the render is refused before anything is
    written, and the files that were there stay as they were."""
    glsl = tmp_path / "glsl"
    shutil.copytree(ROOT / "glsl", glsl)
    lighting = glsl / "lighting/shade_lights.frag"
    lighting.write_text(lighting.read_text().replace("out_radiance = vec4(radiance, 1.0);",
                                                     "out_radiance = vec4(radiance * 1e30 * 1e30, 1.0);"))
    png, npy = out_dir / "x.png", out_dir / "x.npy"
    png.write_bytes(b"old png")
    npy.write_bytes(b"old npy")
    result = vct("render", CORNELL, "--out", png, "--hdr", npy, "--shaders", glsl, *SMALL)
    assert_one_line_error(result, CORNELL, "radiance", "NaN or infinite")
    assert png.read_bytes() == b"old png" and npy.read_bytes() == b"old npy"
    assert sorted(p.name for p in out_dir.iterdir()) == ["x.npy", "x.png"]
