"""Renders spread over processes and machines: `vct batch JOBS` on Ray (a local cluster started
by the command, or one joined by --address) and `vct render --frames N --workers K`.

Facts: a job file's renders come out as `vct render` makes them, a sequence split over two
workers frame for frame equal to one process's, with a manifest line per chunk (outputs,
worker, seconds, result) and a video assembled from a batch's frames; a rerun renders only
what is missing; a job that fails is tried twice, reported by name with exit status 1, and the
others are done; a worker killed in the middle of a chunk is replaced and the chunk done by
another; a bad job file is one line naming its line and field, exit 2, nothing rendered;
Ctrl-C stops the workers and leaves complete frames only; a cluster of two Ray nodes started
by `ray start` is joined by --address.
"""
import json
import os
import signal
import socket
import subprocess
import sys
import time

import imageio_ffmpeg
import numpy as np
import pytest

from test_cli import assert_one_line_error, vct  # tests/ is on sys.path under pytest

from conftest import ROOT, SCENES, rel_mae

pytest.importorskip("ray", reason="vct batch needs Ray (pip install 'vct[batch]'; make test installs it)")

ROOM = SCENES / "animated_room.glb"
BOX = SCENES / "cornell_box.json"
SMALL = {"width": 64, "height": 64, "settings": {"grid": 32}}
RAY = os.path.join(os.path.dirname(sys.executable), "ray")


def write_jobs(path, *jobs):
    path.write_text("".join(json.dumps(job) + "\n" for job in jobs))
    return path


def manifest(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def batch(*args, timeout=300):
    return subprocess.run([sys.executable, "-m", "engine.app.cli", "batch", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)


def test_a_job_file_renders_on_two_workers_as_vct_render_does(tmp_path):
    jobs = write_jobs(tmp_path / "jobs.jsonl",
                      {"name": "box", "scene": str(BOX), "out": "box.png", "hdr": "box.npy", **SMALL},
                      {"name": "room", "scene": str(ROOM), "out": "room_%02d.png", "hdr": "room_%02d.npy", "frames": 6,
                       "video": "room.mp4", **SMALL},
                      {"name": "clip", "scene": str(ROOM), "video": "clip.mp4", "frames": 2, **SMALL})
    result = batch(jobs, "--workers", 2)
    assert result.returncode == 0, result.stderr
    assert "rendered 9 frames on 2 workers" in result.stdout
    lines = manifest(tmp_path / "jobs.manifest.jsonl")
    assert {line["result"] for line in lines} == {"ok"}
    chunks = [line for line in lines if "frames" in line]
    assert sum(line["frames"][1] - line["frames"][0] + 1 for line in chunks) == 9
    assert all(line["worker"] and line["seconds"] > 0 for line in chunks)
    assert all(os.path.isfile(path) for line in lines for path in line["outputs"])
    assert {(line["job"], os.path.basename(line["outputs"][0])) for line in lines if "frames" not in line} == {
        ("room", "room.mp4"), ("clip", "clip.mp4")}
    room_chunks = [line for line in chunks if line["job"] == "room"]
    assert len(room_chunks) == 2  # the sequence in two contiguous chunks, one a worker
    one = vct("render", ROOM, "--frames", 6, "--width", 64, "--height", 64, "--grid", 32,
              "--out", tmp_path / "one_%02d.png", "--hdr", tmp_path / "one_%02d.npy")
    assert one.returncode == 0, one.stderr
    for i in range(6):
        assert rel_mae(np.load(tmp_path / f"room_{i:02d}.npy"), np.load(tmp_path / f"one_{i:02d}.npy")) <= 0.01
    single = vct("render", BOX, "--width", 64, "--height", 64, "--grid", 32, "--out", tmp_path / "b.png",
                 "--hdr", tmp_path / "b.npy")
    assert single.returncode == 0 and rel_mae(np.load(tmp_path / "box.npy"), np.load(tmp_path / "b.npy")) <= 0.01
    reader = imageio_ffmpeg.read_frames(str(tmp_path / "room.mp4"))
    assert next(reader)["size"] == (64, 64) and len(list(reader)) == 6
    assert len(list(imageio_ffmpeg.read_frames(str(tmp_path / "clip.mp4")))) == 3  # its metadata, then 2 frames
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []  # the clip's frames removed

    # A rerun renders nothing; with a frame gone, that frame alone.
    stamps = {p: p.stat().st_mtime_ns for p in tmp_path.glob("room_*.png")}
    again = batch(jobs, "--workers", 2)
    assert again.returncode == 0 and "nothing to render (3 of 3 jobs complete before)" in again.stdout
    (tmp_path / "room_03.png").unlink()
    missing = batch(jobs, "--workers", 2)
    assert missing.returncode == 0 and "rendered 1 frame" in missing.stdout
    assert [line.get("frames") for line in manifest(tmp_path / "jobs.manifest.jsonl")[-2:]] == [[3, 3], None]  # then the video
    assert all(p.stat().st_mtime_ns == stamp for p, stamp in stamps.items() if p.name != "room_03.png")


def test_vct_render_workers_equals_one_process(tmp_path):
    common = [ROOM, "--frames", 4, "--fps", 2, "--width", 64, "--height", 64, "--grid", 32, "--samples", 1]
    spread = vct("render", *common, "--workers", 2, "--hdr", tmp_path / "w_%d.npy", "--out", tmp_path / "w_%d.png")
    assert spread.returncode == 0, spread.stderr
    assert "2 workers" in spread.stdout
    one = vct("render", *common, "--hdr", tmp_path / "s_%d.npy", "--out", tmp_path / "s_%d.png")
    assert one.returncode == 0, one.stderr
    frames = [np.load(tmp_path / f"s_{i}.npy") for i in range(4)]
    assert rel_mae(frames[0], frames[3]) > 0.02  # the animation moved things
    for i in range(4):
        assert rel_mae(np.load(tmp_path / f"w_{i}.npy"), frames[i]) <= 0.01


def test_a_failing_job_is_tried_twice_named_and_the_others_are_done(tmp_path):
    (tmp_path / "broken.json").write_text('{"camera": ')
    jobs = write_jobs(tmp_path / "jobs.jsonl", {"name": "broken", "scene": "broken.json", "out": "broken.png"},
                      {"name": "fine", "scene": str(BOX), "out": "fine.png", **SMALL})
    result = batch(jobs, "--workers", 2)
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert lines[-1].startswith("vct: error: 1 of 2 jobs failed: \"broken\"") and "malformed JSON" in lines[-1]
    assert "Traceback" not in result.stderr
    failed = [line for line in manifest(tmp_path / "jobs.manifest.jsonl") if line["job"] == "broken"]
    assert [line["try"] for line in failed] == [1, 2] and all(line["result"] == "failed" for line in failed)
    assert (tmp_path / "fine.png").is_file() and not (tmp_path / "broken.png").exists()


def test_a_worker_killed_in_a_chunk_is_replaced_and_its_chunk_done_again(tmp_path):
    jobs = write_jobs(tmp_path / "jobs.jsonl", {"name": "room", "scene": str(ROOM), "out": "f_%03d.png", "frames": 48,
                                                  "width": 48, "height": 48, "settings": {"grid": 16, "samples": 1}})
    process = subprocess.Popen([sys.executable, "-m", "engine.app.cli", "batch", str(jobs), "--workers", "2"], cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    log = tmp_path / "jobs.manifest.jsonl"
    deadline = time.monotonic() + 120
    while not (log.exists() and log.read_text().strip()) and time.monotonic() < deadline:
        time.sleep(0.05)
    worker = manifest(log)[0]["worker"]
    os.kill(int(worker.rsplit(":", 1)[1]), signal.SIGKILL)  # busy with its next chunk, or idle for one
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, err
    lines = manifest(log)
    assert any(line["result"] == "failed" and line["error"] == "the worker died" for line in lines)
    assert all(os.path.isfile(tmp_path / f"f_{i:03d}.png") for i in range(48))


@pytest.mark.parametrize("line, mentions", [
    ('{"scene": "%s", "out": "x.png", "widht": 64}', ("jobs.jsonl:1", 'unknown field "widht"', 'did you mean "width"')),
    ('{"scene": "%s", "out": "x.png", "frames": 0}', ("jobs.jsonl:1", "frames", "at least 1")),
    ('{"scene": "%s", "out": "x.png", "time": 1, "frames": 2}', ("jobs.jsonl:1", "time", "not both")),
    ('{"scene": "nope.json", "out": "x.png"}', ("jobs.jsonl:1", "scene", "file not found")),
    ('{"scene": "%s", "out": "x.png", "settings": {"gird": 32}}', ("jobs.jsonl:1", "settings", 'did you mean "grid"')),
    ('{"scene": "%s", "out": "x.png", "settings": {"grid": 33}}', ("jobs.jsonl:1", "settings.grid")),
    ('{"scene": "%s", "out": "x_%%d.png", "hdr": "x.npy", "frames": 2}', ("jobs.jsonl:1", "hdr", "%d")),
    ('{"scene": "%s"}', ("jobs.jsonl:1", "out", "video")),
    ('{"scene": "%s", "out": "x.png"', ("jobs.jsonl:1", "malformed JSON")),
])
def test_a_bad_job_file_is_one_line_naming_line_and_field(tmp_path, line, mentions):
    text = line % BOX if "%s" in line else line
    (tmp_path / "jobs.jsonl").write_text(text + "\n")
    result = batch(tmp_path / "jobs.jsonl", timeout=60)
    assert_one_line_error(result, *mentions)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["jobs.jsonl"]  # nothing rendered, no manifest


def test_ctrl_c_stops_the_workers_and_leaves_complete_frames_only(tmp_path):
    jobs = write_jobs(tmp_path / "jobs.jsonl", {"scene": str(ROOM), "out": "f_%03d.png", "hdr": "f_%03d.npy", "frames": 200,
                                                  "width": 96, "height": 96})
    process = subprocess.Popen([sys.executable, "-m", "engine.app.cli", "batch", str(jobs), "--workers", "2"], cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob("f_*.npy")) and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 128 + signal.SIGINT, err
    assert "Traceback" not in err
    names = {p.name for p in tmp_path.iterdir()} - {"jobs.jsonl", "jobs.manifest.jsonl"}
    assert names and not any(name.endswith(".tmp") for name in names)
    frames = {name[:5] for name in names}
    assert len(frames) < 200 and names == {f"{frame}.{kind}" for frame in frames for kind in ("png", "npy")}


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_cluster_of_two_nodes_started_by_ray_start_is_joined_by_address(tmp_path):
    port = _free_port()
    env = dict(os.environ, RAY_AUTH_MODE="token")
    started = subprocess.run([RAY, "start", "--head", f"--port={port}", "--num-cpus=1", "--include-dashboard=false",
                              "--disable-usage-stats"], capture_output=True, text=True, timeout=120, env=env)
    try:
        assert started.returncode == 0, started.stderr
        second = subprocess.run([RAY, "start", f"--address=127.0.0.1:{port}", "--num-cpus=1", "--disable-usage-stats"],
                                capture_output=True, text=True, timeout=120, env=env)
        assert second.returncode == 0, second.stderr
        jobs = write_jobs(tmp_path / "jobs.jsonl", {"scene": str(ROOM), "out": "f_%d.png", "frames": 4, **SMALL})
        result = batch(jobs, "--address", f"127.0.0.1:{port}")
        assert result.returncode == 0, result.stderr
        assert "on 2 workers" in result.stdout  # one a node
        assert len({line["worker"] for line in manifest(tmp_path / "jobs.manifest.jsonl")}) == 2
    finally:
        subprocess.run([RAY, "stop", "--force"], capture_output=True, timeout=120)


def test_an_address_where_no_cluster_listens_is_one_line(tmp_path):
    jobs = write_jobs(tmp_path / "jobs.jsonl", {"scene": str(BOX), "out": "x.png"})
    result = batch(jobs, "--address", f"127.0.0.1:{_free_port()}", timeout=60)
    assert_one_line_error(result, "--address", "cannot join the Ray cluster")
    assert not (tmp_path / "x.png").exists()

