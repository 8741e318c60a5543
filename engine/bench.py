"""`vct bench`: per-pass milliseconds (median over frames after warm-up, each pass timed with
ctx.finish() and the wall clock) for each grid size, optionally with the error against a
reference radiance image, so cost and accuracy can be read side by side. Frames are dynamic
frames as in the viewer: everything is rebuilt every frame, and with bounces 0 each frame adds
one bounce on top of the previous frame's voxel radiance (converging over the warm-up)."""
import statistics
import time

import numpy as np

from .settings import VOXEL_MODES

PASS_ORDER = ("shadow", "gbuffer", "lighting", "voxelize", "mipmap", "bounces", "cone_trace",
              "voxel_view", "gbuffer_view")


def relative_errors(radiance, reference):
    """relMAE = sum|c - r| / sum r, relMSE = sum (c - r)^2 / sum r^2, mean luminance ratio."""
    diff = radiance.astype(np.float64) - reference
    return {"rel_mae": float(np.abs(diff).sum() / reference.sum()),
            "rel_mse": float((diff ** 2).sum() / (reference.astype(np.float64) ** 2).sum()),
            "luminance_ratio": float(radiance.mean() / reference.mean())}


def benchmark(scene, renderer, settings, grids, frames, warmup, reference=None):
    rows = []
    for grid in grids if settings.mode in VOXEL_MODES else [settings.grid]:
        s = settings.replace(grid=grid)
        renderer.measure = False
        renderer.feedback = True
        for _ in range(warmup):
            renderer.render_frame(scene, s)
        renderer.measure = True
        per_pass, totals = {}, []
        for _ in range(frames):
            renderer.ctx.finish()
            start = time.perf_counter()
            renderer.render_frame(scene, s)
            renderer.ctx.finish()
            totals.append((time.perf_counter() - start) * 1000.0)
            for name, ms in renderer.timings.items():
                per_pass.setdefault(name, []).append(ms)
        row = {"grid": grid if s.mode in VOXEL_MODES else None, "mode": s.mode, "bounces": s.bounces, "bounce_iterations": renderer.bounce_iterations,
               "passes_ms": {name: statistics.median(per_pass[name]) for name in PASS_ORDER if name in per_pass},
               "total_ms": statistics.median(totals), "draw_calls": renderer.geometry.draw_calls}
        if reference is not None:  # the accuracy of this configuration, converged
            renderer.feedback = False
            renderer.measure = False
            renderer.render_frame(scene, s)
            row.update(relative_errors(renderer.radiance(), reference))
            renderer.feedback = True
        rows.append(row)
    renderer.measure = False
    return rows


def format_table(rows):
    names = [n for n in PASS_ORDER if any(n in r["passes_ms"] for r in rows)]
    has_error = any("rel_mae" in r for r in rows)
    header = ["grid"] + names + ["total"] + (["relMAE", "lum ratio"] if has_error else [])
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        cells = [f"{r['grid']}^3" if r["grid"] else "-"] + [f"{r['passes_ms'].get(n, 0.0):.1f}" for n in names] + [f"{r['total_ms']:.1f}"]
        if has_error:
            cells += [f"{r['rel_mae']:.3f}", f"{r['luminance_ratio']:.3f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)
