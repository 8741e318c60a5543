"""This renderer and Godot 3's GIProbe (../shared/peers/godot-giprobe) timed in the same run on
the Cornell box, side by side with their ratio, so the comparison holds on a shared, noisy
machine.

    .venv/bin/python tools/bench_peers.py [--grid 128] [--size 256x256] [--frames 10] [--json out.json]

Runs `vct bench` (static, camera, light and object frames) and the peer's time.sh (median frame with
voxels baked once: the counterpart of a static frame), then prints one table."""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PEER = ROOT.parent / "shared" / "peers" / "godot-giprobe" / "time.sh"


def godot_median_ms(size, grid):
    result = subprocess.run([str(PEER), size, str(grid)], capture_output=True, text=True, timeout=1200)
    match = re.search(r"median_ms=([0-9.]+)", result.stdout)
    if not match:
        sys.exit(f"bench_peers: {PEER} gave no timing ({(result.stdout + result.stderr).strip()[-300:]})")
    return float(match.group(1)), result.stdout.strip()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grid", type=int, default=128)
    parser.add_argument("--size", default="256x256")
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--json", help="also write the records (ours and the peer's) to this file")
    args = parser.parse_args()
    if not PEER.exists():
        sys.exit(f"bench_peers: the peer is missing ({PEER})")
    width, height = args.size.split("x")
    with tempfile.TemporaryDirectory() as tmp:
        ours_json = Path(tmp) / "ours.json"
        subprocess.run([str(ROOT / ".venv" / "bin" / "vct"), "bench", str(ROOT / "scenes" / "cornell_box.json"),
                        "--grids", str(args.grid), "--width", width, "--height", height, "--frames", str(args.frames),
                        "--json", str(ours_json)], check=True, env=os.environ)
        ours = json.loads(ours_json.read_text())
    godot_ms, godot_line = godot_median_ms(args.size, args.grid)
    print(godot_line)
    print(f"\n| frame ({args.size}, grid {args.grid}) | this renderer | Godot 3 GIProbe | ratio |")
    print("|---|---|---|---|")
    for record in ours:
        print(f"| {record['frame']} | {record['total_ms']:.1f} ms | {godot_ms:.1f} ms | {record['total_ms'] / godot_ms:.2f} |")
    if args.json:
        peer = {"scene": "cornell_box", "grid": args.grid, "frame": "godot3-giprobe", "width": int(width),
                "height": int(height), "total_ms": godot_ms, "passes": {}}
        Path(args.json).write_text(json.dumps(ours + [peer], indent=2))


if __name__ == "__main__":
    main()
