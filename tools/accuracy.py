"""Accuracy table: the Cornell box rendered at each grid size and bounce count, compared with
the Mitsuba references in ../shared/reference (relative MAE, relative MSE, mean-luminance ratio).

    .venv/bin/python tools/accuracy.py [--grids 32,64,128,256] [--bounces 1,2,3,0] [--json out.json]

bounces 1 is compared with cornell_box_1bounce.npy (direct + one bounce), every other count
with cornell_box_gi.npy (all bounces); 0 means iterate to convergence (the default)."""
import argparse
import json
import time
from pathlib import Path

import numpy as np

import engine
from engine.bench import relative_errors

ROOT = Path(__file__).resolve().parent.parent
REFERENCE = ROOT.parent / "shared" / "reference"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "cornell_box.json"))
    parser.add_argument("--reference-dir", default=str(REFERENCE))
    parser.add_argument("--grids", default="32,64,128,256")
    parser.add_argument("--bounces", default="1,2,3,0")
    parser.add_argument("--json", help="also write the rows as JSON")
    args = parser.parse_args()
    scene = engine.load_scene(args.scene)
    references = {name: np.load(Path(args.reference_dir) / f"cornell_box_{name}.npy").astype(np.float64)
                  for name in ("direct", "1bounce", "gi")}
    rows = []
    print("| grid | bounces | reference | relMAE | relMSE | luminance ratio | seconds |")
    print("|---|---|---|---|---|---|---|")
    with engine.Renderer(scene.camera.width, scene.camera.height) as renderer:
        direct = renderer.render(scene, mode="direct")
        row = {"grid": None, "bounces": "direct", "reference": "direct", **relative_errors(direct, references["direct"])}
        print(f"| - | direct only | direct | {row['rel_mae']:.4f} | {row['rel_mse']:.5f} | {row['luminance_ratio']:.3f} | - |")
        rows.append(row)
        for grid in [int(g) for g in args.grids.split(",")]:
            for bounces in [int(b) for b in args.bounces.split(",")]:
                start = time.perf_counter()
                radiance = renderer.render(scene, mode="gi", grid=grid, bounces=bounces)
                seconds = time.perf_counter() - start
                name = "1bounce" if bounces == 1 else "gi"
                row = {"grid": grid, "bounces": bounces or "converged", "reference": name, "seconds": seconds,
                       "bounce_iterations": renderer.bounce_iterations, **relative_errors(radiance, references[name])}
                rows.append(row)
                print(f"| {grid}^3 | {row['bounces']} | {name} | {row['rel_mae']:.4f} | {row['rel_mse']:.5f} | "
                      f"{row['luminance_ratio']:.3f} | {seconds:.1f} |", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
