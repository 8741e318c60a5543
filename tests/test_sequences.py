"""Sequences from the command line: `vct render --time`, `--frames N --fps F --start T0` into
numbered files and an H.264 video, `--orbit`; temporal stability.

Facts: frame i of a sequence is the scene at T0 + i / fps, equal to a single `--time` render
at that time within 1 %; the numbered files and the video hold every frame at the image's size
(odd sizes padded for the video); `--orbit` turns the camera once about the vertical axis
through its look-at point, keeping its distance; where one object moves, a wall away from it
changes by less than 0.5 % from frame to frame, and the viewer's progressive frames after it
moved converge without a pattern of voxel classes; `vct bench` times animated frames where
the scene has animations; an interrupted sequence leaves the frames done
so far complete and no partial file; malformed sequence options are one line, exit 2, nothing
written.
"""
import json
import signal
import subprocess
import sys
import time

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

import engine
from engine.formats.sequence import orbit
from test_animation import animated_gltf  # tests/ is on sys.path under pytest
from test_cli import assert_one_line_error, vct

from conftest import ROOT, SCENES, interruptible, rel_mae

ROOM = SCENES / "animated_room.glb"
SMALL = ("--width", "96", "--height", "96", "--grid", "32")


def test_frame_i_of_a_sequence_equals_a_single_render_at_its_time(tmp_path):
    result = vct("render", ROOM, *SMALL, "--frames", "3", "--fps", "2", "--start", "0.5",
                 "--out", tmp_path / "f_%02d.png", "--hdr", tmp_path / "f_%02d.npy")
    assert result.returncode == 0, result.stderr
    assert "wrote 3 frames" in result.stdout and "t = 0.5..1.5 s" in result.stdout
    frames = [np.load(tmp_path / f"f_{i:02d}.npy") for i in range(3)]
    assert all(Image.open(tmp_path / f"f_{i:02d}.png").size == (96, 96) for i in range(3))
    assert rel_mae(frames[0], frames[2]) > 0.02  # the animation moved things
    single = vct("render", ROOM, *SMALL, "--time", "1.5", "--out", tmp_path / "one.png", "--hdr", tmp_path / "one.npy")
    assert single.returncode == 0, single.stderr
    assert rel_mae(frames[2], np.load(tmp_path / "one.npy").astype(np.float64)) < 0.01


def test_the_video_holds_every_frame_at_the_image_size(tmp_path):
    result = vct("render", ROOM, "--width", "65", "--height", "48", "--grid", "16", "--frames", "5",
                 "--video", tmp_path / "room.mp4")
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["room.mp4"]  # no temporary left
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "room.mp4"))
    meta = next(reader)
    frames = list(reader)
    assert meta["size"] == (66, 48) and meta["codec"] == "h264"  # the odd width padded by a pixel
    assert len(frames) == 5 and max(np.frombuffer(f, np.uint8).mean() for f in frames) > 20


def test_orbit_turns_the_camera_about_the_vertical_through_its_look_at_point():
    camera = engine.load_scene(SCENES / "cornell_box.json").camera
    half = orbit(camera, 0.5)
    assert np.allclose(half.look_at, camera.look_at)
    offset, turned = camera.position - camera.look_at, half.position - half.look_at
    assert np.isclose(np.linalg.norm(turned), np.linalg.norm(offset))
    assert np.allclose(turned, [-offset[0], offset[1], -offset[2]])
    assert np.allclose(orbit(camera, 1.0).position, camera.position)


def test_orbit_frames_differ_and_start_at_the_scene_camera(tmp_path):
    result = vct("render", SCENES / "cornell_box.json", *SMALL, "--frames", "4", "--orbit",
                 "--hdr", tmp_path / "o_%d.npy", "--out", tmp_path / "o_%d.png")
    assert result.returncode == 0, result.stderr
    plain = vct("render", SCENES / "cornell_box.json", *SMALL, "--hdr", tmp_path / "p.npy", "--out", tmp_path / "p.png")
    assert plain.returncode == 0, plain.stderr
    frames = [np.load(tmp_path / f"o_{i}.npy").astype(np.float64) for i in range(4)]
    assert rel_mae(frames[0], np.load(tmp_path / "p.npy").astype(np.float64)) < 0.01
    assert rel_mae(frames[1], frames[0]) > 0.1


def moving_card_scene(tmp_path):
    """The Cornell box with a 10 cm card 5 cm before the back wall that slides 10 cm to the
    right in a second (then starts again)."""
    animated_gltf(tmp_path / "card.glb", [("Card", "translation", [0, 1], [[0, 0, 0], [1, 0, 0]], "LINEAR")])
    scene = json.loads((SCENES / "cornell_box.json").read_text())
    scene["objects"].append({"name": "Card", "type": "mesh", "file": "card.glb", "material": "white",
                             "translation": [0.1, -0.1, -0.95], "rotation": [90, 0, 0], "scale": [0.1, 0.1, 0.1]})
    path = tmp_path / "moving.json"
    path.write_text(json.dumps(scene))
    return path


def test_a_wall_away_from_a_moving_object_holds_still_from_frame_to_frame(tmp_path):
    scene = moving_card_scene(tmp_path)
    result = vct("render", scene, "--width", "128", "--height", "128", "--grid", "64", "--frames", "5", "--fps", "4",
                 "--hdr", tmp_path / "m_%d.npy", "--out", tmp_path / "m_%d.png")
    assert result.returncode == 0, result.stderr
    frames = [np.load(tmp_path / f"m_{i}.npy").astype(np.float64) for i in range(5)]
    right_wall = (slice(20, 100), slice(112, 124))  # the red wall, across the box from the card
    assert frames[0][right_wall].mean() > 0.01
    for before, after in zip(frames, frames[1:]):
        change = np.abs(after[right_wall] - before[right_wall]).sum(axis=-1) / before[right_wall].sum(axis=-1)
        assert change.max() < 0.005, change.max()
    assert rel_mae(frames[0], frames[3]) > 1e-3  # the card did move


def test_progressive_frames_after_an_object_moved_converge_without_class_patterns():
    """The viewer's frames after an object moved update one interleave class of voxels each
    (--bounce-interleave 4): the image's deviation from the settled frame is smooth, its part
    that a 5x5 blur does not hold (the pattern of classes, 2 voxels apart) under 2.5 levels of
    the 8-bit image in 99 % of the pixels of every frame, and it settles within 40 frames (the
    lecture's six cones, with which the viewer converges before refining)."""
    from scipy.ndimage import uniform_filter

    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(128, 128) as renderer:
        renderer.progressive = True
        settings = renderer.settings.replace(grid=64, diffuse_cones="six")
        for _ in range(200):
            renderer.render_frame(scene, settings)
            if renderer.settled:
                break
        box = scene.root.find("Short Box")
        box.translation = box.translation + [0.1, 0.0, 0.0]
        frames = []
        while not renderer.settled and len(frames) < 40:
            renderer.render_frame(scene, settings)
            frames.append(renderer.tonemapped().astype(np.float64).mean(axis=-1))
    assert renderer.settled, f"not settled after {len(frames)} frames"
    for frame in frames:
        deviation = frame - frames[-1]
        pattern = deviation - uniform_filter(deviation, 5)
        assert np.percentile(np.abs(pattern), 99) < 2.5


def test_an_interrupted_sequence_leaves_complete_frames_and_no_partial_file(tmp_path):
    process = subprocess.Popen([sys.executable, "-m", "engine.app.cli", "render", str(ROOM), *SMALL, "--frames", "200",
                                "--out", str(tmp_path / "f_%03d.png"), "--video", str(tmp_path / "v.mp4")],
                               cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=interruptible)
    deadline = time.monotonic() + 120
    while not (tmp_path / "f_002.png").exists() and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.1)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 128 + signal.SIGINT, stderr
    left = sorted(p.name for p in tmp_path.iterdir())
    assert "v.mp4" not in left and not [name for name in left if name.startswith(".vct-")], left
    assert len(left) >= 3
    for name in left:
        with Image.open(tmp_path / name) as image:
            image.load()  # a truncated PNG raises here
            assert image.size == (96, 96)


@pytest.mark.parametrize("args, mentions", [
    (("--frames", "0"), ["--frames", "at least 1"]),
    (("--frames", "100001"), ["--frames", "at most 100000"]),
    (("--frames", "2", "--fps", "0"), ["--fps", "greater than 0"]),
    (("--frames", "2", "--fps", "-3"), ["--fps"]),
    (("--frames", "2", "--out", "{out}/same.png"), ["--out", "2 frames need a %d"]),
    (("--frames", "2", "--out", "{out}/f_%d_%d.png"), ["--out", "one %d"]),
    (("--video", "{out}/missing/v.mp4"), ["--video", "directory does not exist"]),
    (("--video", "{out}/v.avi"), ["--video", ".mp4"]),
    (("--frames", "2", "--time", "1"), ["--time"]),
    (("--time", "nan"), ["--time", "finite"]),
])
def test_malformed_sequence_options_are_one_line_and_write_nothing(tmp_path, args, mentions):
    out = tmp_path / "out"
    out.mkdir()
    args = [a.replace("{out}", str(out)) for a in args]
    if "--out" not in args and "--video" not in args:
        args += ["--out", str(out / "f_%d.png")]
    assert_one_line_error(vct("render", ROOM, *SMALL, *args), *mentions)
    assert not list(out.iterdir())


def test_bench_times_animated_frames_for_a_scene_with_animations(tmp_path):
    result = vct("bench", ROOM, "--width", "64", "--height", "64", "--grids", "16", "--frames", "2", "--warmup", "1",
                 "--json", tmp_path / "b.json")
    assert result.returncode == 0, result.stderr
    rows = json.loads((tmp_path / "b.json").read_text())
    animated, = [row for row in rows if row["frame"] == "animated"]
    assert animated["moves"] == 'animations "Play", "Dolly"' and animated["total_ms"] > 0
    assert "voxelize" in animated["passes"]  # the animation moves objects: their voxels follow
    # The host's time of a frame (issuing its work) apart from the GPU's (its passes'), per kind.
    assert all(0 < row["host_ms"] and 0 < row["gpu_ms"] and sum(row["passes"].values()) == pytest.approx(row["gpu_ms"], rel=0.5)
               for row in rows)
    vct("bench", SCENES / "cornell_box.json", "--width", "32", "--height", "32", "--grids", "16", "--frames", "1",
        "--warmup", "0", "--json", tmp_path / "c.json")
    assert "animated" not in {row["frame"] for row in json.loads((tmp_path / "c.json").read_text())}
