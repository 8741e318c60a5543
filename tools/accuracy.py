"""Accuracy tables: scenes rendered at each grid size and bounce count, compared with their
path-traced references (relative MAE, relative MSE, mean-luminance ratio).

    .venv/bin/python tools/accuracy.py [--grids 32,64,128,256] [--bounces 1,0] [--json out.json]
    .venv/bin/python tools/accuracy.py --scenes all --bounces 0
    .venv/bin/python tools/accuracy.py --samples 1     # the pixel centres, no anti-aliasing
    .venv/bin/python tools/accuracy.py --diffuse-cones six     # the lecture's six diffuse cones, not tiled

The Cornell box is compared with ../shared/reference (`bounces 1` with cornell_box_1bounce.npy,
every other count with cornell_box_gi.npy, and direct light alone with cornell_box_direct.npy);
the scenes of scenes/references (scene files, and glTF files without one) with their
NAME_gi.npy and NAME_direct.npy (direct light alone: from lights and emissive surfaces, at the
renderer's default grid where surfaces emit, since the voxels shadow their light). 0 bounces means iterate to convergence.
Images are anti-aliased as `vct render` makes them (--samples, default HEADLESS_SAMPLES): the
references' pixels are box-filtered."""
import argparse
import json
import time
from pathlib import Path

import numpy as np

import engine
from engine.app.bench import relative_errors
from engine.frame.settings import DIFFUSE_CONE_SETS, HEADLESS_SAMPLES, RenderSettings
from engine.scene.emitters import scene_emits

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "reference"
OURS = ROOT / "scenes" / "references"


def cases(names):
    """(scene name, scene file, {"direct" | "1bounce" | "gi": reference file}) of the scenes
    `names` ("cornell_box", "all", or scene names separated by commas)."""
    wanted = None if names == "all" else set(names.split(","))
    if wanted is None or "cornell_box" in wanted:
        yield "cornell_box", ROOT / "scenes" / "cornell_box.json", {k: SHARED / f"cornell_box_{k}.npy" for k in ("direct", "1bounce", "gi")}
    # Scene files, and glTF files that are scenes of their own (no scene file of their name).
    files = [p for p in OURS.glob("*.json") if not p.name.endswith(".meta.json")]
    files += [p for p in OURS.glob("*.gl[bt]*") if not p.with_suffix(".json").exists()]
    for scene in sorted(files):
        if wanted is not None and scene.stem not in wanted:
            continue
        refs = {k: OURS / f"{scene.stem}_{k}.npy" for k in ("direct", "gi")}
        yield scene.stem, scene, {k: path for k, path in refs.items() if path.exists()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="cornell_box", help='"all", or scene names separated by commas')
    parser.add_argument("--grids", default="32,64,128,256")
    parser.add_argument("--bounces", default="1,0")
    parser.add_argument("--samples", type=int, default=HEADLESS_SAMPLES, help="jittered samples a pixel (1: its centre)")
    parser.add_argument("--diffuse-cones", choices=DIFFUSE_CONE_SETS, default=RenderSettings().diffuse_cones,
                        help="the diffuse cones: the lecture's six, or each traced as seven narrower ones")
    parser.add_argument("--json", help="also write the rows as JSON")
    args = parser.parse_args()
    rows = []
    print("| scene | grid | bounces | reference | relMAE | relMSE | luminance ratio | seconds |")
    print("|---|---|---|---|---|---|---|---|")
    for name, scene_file, refs in cases(args.scenes):
        scene = engine.load_scene(scene_file)
        references = {k: np.load(path).astype(np.float64) for k, path in refs.items()}
        # The image size of the references (a glTF camera's own default size may differ).
        scene.camera.height, scene.camera.width = next(iter(references.values())).shape[:2]
        with engine.Renderer(scene.camera.width, scene.camera.height) as renderer:
            if "direct" in references:
                # Emitters' shadows are cones through the voxels: their direct light depends on the grid.
                grid = renderer.settings.grid if scene_emits(scene) else None
                direct = renderer.render(scene, mode="direct", samples=args.samples)
                row = {"scene": name, "grid": grid, "bounces": "direct", "reference": "direct",
                       **relative_errors(direct, references["direct"])}
                print(f"| {name} | {f'{grid}^3' if grid else '-'} | direct only | direct | {row['rel_mae']:.4f} | "
                      f"{row['rel_mse']:.5f} | {row['luminance_ratio']:.3f} | - |", flush=True)
                rows.append(row)
            for grid in [int(g) for g in args.grids.split(",")]:
                for bounces in [int(b) for b in args.bounces.split(",")]:
                    kind = "1bounce" if bounces == 1 and "1bounce" in references else "gi"
                    if kind not in references or (bounces == 1 and kind == "gi"):
                        continue
                    start = time.perf_counter()
                    radiance = renderer.render(scene, mode="gi", grid=grid, bounces=bounces, samples=args.samples,
                                               diffuse_cones=args.diffuse_cones)
                    seconds = time.perf_counter() - start
                    row = {"scene": name, "grid": grid, "bounces": bounces or "converged", "reference": kind,
                           "seconds": seconds, "bounce_iterations": renderer.bounce_iterations,
                           **relative_errors(radiance, references[kind])}
                    rows.append(row)
                    print(f"| {name} | {grid}^3 | {row['bounces']} | {kind} | {row['rel_mae']:.4f} | {row['rel_mse']:.5f} | "
                          f"{row['luminance_ratio']:.3f} | {seconds:.1f} |", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
