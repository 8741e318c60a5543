"""Throughput of a sequence rendered by one process and by Ray workers (`vct render --frames N
--workers K`), in frames a second, each run a fresh command (Python start, Ray start, each
worker's EGL context and shaders included, as a user's run has them).

    .venv/bin/python tools/batch_throughput.py [--frames 48] [--size 128x128] [--workers 1,2] [--diffuse-cones six]
"""
import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from engine.frame.settings import DIFFUSE_CONE_SETS, RenderSettings

ROOT = Path(__file__).resolve().parent.parent


def seconds(args):
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "engine.app.cli", "render", *args, "--quiet"], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "animated_room.glb"))
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--size", default="128x128")
    parser.add_argument("--grid", type=int, default=64)
    parser.add_argument("--workers", default="1,2")
    parser.add_argument("--diffuse-cones", choices=DIFFUSE_CONE_SETS, default=RenderSettings().diffuse_cones,
                        help="the diffuse cones, as vct render's option")
    args = parser.parse_args()
    width, height = args.size.split("x")
    common = [args.scene, "--frames", str(args.frames), "--width", width, "--height", height, "--grid", str(args.grid),
              "--diffuse-cones", args.diffuse_cones]
    print(f"| {args.frames} frames of {Path(args.scene).name}, {args.size}, grid {args.grid}, {args.diffuse_cones} cones "
          "| seconds | frames/s | against one process |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        one = seconds(common + ["--out", f"{folder}/one_%04d.png"])
        print(f"| one process | {one:.1f} | {args.frames / one:.2f} | 1.00 |", flush=True)
        for workers in [int(k) for k in args.workers.split(",")]:
            spent = seconds(common + ["--out", f"{folder}/w{workers}_%04d.png", "--workers", str(workers)])
            print(f"| {workers} worker{'s' if workers > 1 else ''} | {spent:.1f} | {args.frames / spent:.2f} | {one / spent:.2f} |",
                  flush=True)


if __name__ == "__main__":
    main()
