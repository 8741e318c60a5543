"""`vct bench`: per-pass milliseconds of the frames a viewer renders, for each grid size.

Kinds of frame, each timed over a path after the radiance has settled (progressive bounces,
as in the viewer):
- static: the camera turns where it stands (its view sweeps a small circle), nothing else
          changes;
- camera: the camera flies along its view at walking speed (WALKING_SPEED, ANIMATION_FPS
          frames a second), turning back after a quarter of the scene's size;
- light:  a light moves along a circle every frame (its shadow map, light injection, one
          bounce re-gathering one interleave class, the face views);
- object: an object moves back and forth every frame (its voxels, every shadow map, the rest
          as for a light);
- animated: for scenes with animations, they play at ANIMATION_FPS frames a second of their
          time (whatever they move: objects, lights, the camera).
Each kind is rendered twice over its path. First the frames one after another with one finish
at the end, as a viewer renders them: the frame time is their throughput (the wall time over
the frames), and the host time of each frame is the wall time of its Python and of the GL
calls that only record work, the calls that do the work on a software rasterizer (draws,
dispatches, barriers, finishes, reads: GL_WORK) timed apart and left out. Then again with each pass timed
(engine/gpu/timing.py: GL timer queries read a few frames later on a GPU, the wall clock around
a finish on llvmpipe): the median per pass and the slowest frame. Optionally the error of each
grid's converged image against a reference radiance image, so cost and accuracy can be read
side by side.
"""
import math
import resource
import statistics
import time
from contextlib import contextmanager

import moderngl
import numpy as np

from ..core.errors import warn
from ..frame.settings import MODE_TABLE
from ..gpu.shaders import ProgramHandle
from ..scene.emitters import scene_emits

FRAME_KINDS = ("static", "camera", "light", "object", "animated")
ANIMATION_FPS = 30.0  # animation time per frame of the animated and camera kinds: 1/30 s
WALKING_SPEED = 1.4   # m/s, the camera kind's
PASS_ORDER = ("pose", "shadow", "gbuffer", "lighting", "emitters", "environment", "voxelize", "emission_mipmap",
              "emitter_light", "sky_light", "inject", "classes", "gather", "faces", "mipmap", "totals", "cone_trace", "transparent",
              "temporal", "voxel_view", "gbuffer_view")
SETTLE_FRAMES = 2000  # progressive frames allowed for the radiance to settle (and refine) before timing
# The GL calls that do a frame's work where the GPU is the CPU (llvmpipe runs draws and
# dispatches as they are issued, and a memory barrier waits for them): left out of the host time.
GL_WORK = ((moderngl.VertexArray, ("render", "render_indirect")), (ProgramHandle, ("run", "run_indirect")),
           (moderngl.Context, ("finish", "memory_barrier")), (moderngl.Buffer, ("read",)), (moderngl.Texture, ("read",)),
           (moderngl.Texture3D, ("read",)), (moderngl.Framebuffer, ("read",)))


def relative_errors(radiance, reference):
    """relMAE = sum|c - r| / sum r, relMSE = sum (c - r)^2 / sum r^2, mean luminance ratio."""
    diff = radiance.astype(np.float64) - reference
    return {"rel_mae": float(np.abs(diff).sum() / reference.sum()),
            "rel_mse": float((diff ** 2).sum() / (reference.astype(np.float64) ** 2).sum()),
            "luminance_ratio": float(radiance.mean() / reference.mean())}


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def moving_object(scene):
    """The node a benchmark moves: the smallest mesh instance of the scene (by bounds)."""
    sizes = [(float(np.linalg.norm(np.subtract(*node.mesh.bounds(world)[::-1]))), node.name, node)
             for node, world in scene.drawables()]
    return min(sizes, key=lambda s: (s[0], s[1]))[2] if sizes else None


class FramePath:
    """Per-frame changes of one frame kind, applied to the scene before each frame and undone
    by `restore()`."""

    def __init__(self, scene, kind):
        self.scene, self.kind = scene, kind
        self.home = scene.camera
        self.animations = list(scene.animations()) if kind == "animated" else []
        lo, hi = scene.bounds()
        self.size = float(np.max(hi - lo)) or 1.0
        camera = scene.camera
        self.camera = (camera.position.copy(), camera.look_at.copy())
        self.flies = kind == "camera"
        lights = [node for node, _ in scene.lights()]
        self.light = lights[0] if lights and kind == "light" else None
        self.light_position = self.light.light.position.copy() if self.light else None
        self.object = moving_object(scene) if kind == "object" else None
        self.translation = self.object.translation.copy() if self.object else None

    @property
    def subject(self):
        if self.animations:
            return "animations " + ", ".join(f'"{name}"' for name in self.animations)
        if self.flies:
            return "camera, flying at walking speed"
        return self.light.name if self.light else self.object.name if self.object else "camera"

    def apply(self, frame):
        if self.animations:
            self.scene.pose_at(frame / ANIMATION_FPS)
            return
        angle = 2.0 * math.pi * frame / 16.0
        position, look_at = self.camera
        if self.flies:  # along the view, there and back: a triangle wave of the distance walked
            reach = 0.25 * self.size
            walked = (WALKING_SPEED * frame / ANIMATION_FPS) % (2.0 * reach)
            offset = (look_at - position) / np.linalg.norm(look_at - position) * min(walked, 2.0 * reach - walked)
            self.scene.camera.position, self.scene.camera.look_at = position + offset, look_at + offset
            return
        # The camera turns where it stands: what it looks at runs along a small circle.
        self.scene.camera.position = position
        self.scene.camera.look_at = look_at + 0.02 * self.size * np.array([math.cos(angle), math.sin(angle), 0.0])
        if self.light is not None:
            self.light.light.position = self.light_position + 0.1 * self.size * np.array([math.cos(angle), 0.0, math.sin(angle)])
        if self.object is not None:
            self.object.translation = self.translation + 0.05 * self.size * np.array([math.sin(angle), 0.0, 0.0])

    def restore(self):
        if self.animations:
            self.scene.camera = self.home
            self.scene.pose_at(0.0)
            return
        self.scene.camera.position, self.scene.camera.look_at = self.camera
        if self.light is not None:
            self.light.light.position = self.light_position
        if self.object is not None:
            self.object.translation = self.translation


def settle(scene, renderer, settings):
    """Render progressive frames until no work is due (the bounces settled, the voxels' light
    done: RadianceSchedule.idle), at most SETTLE_FRAMES; returns whether it is."""
    for _ in range(SETTLE_FRAMES):
        renderer.render_frame(scene, settings)
        if renderer.idle:
            return True
    return False


def warn_unsettled(scene, kinds):
    """One warning line: the radiance had not settled before these kinds' timed frames, which
    then carry the work still due."""
    warn(f"the radiance did not settle within {SETTLE_FRAMES} frames before the {', '.join(kinds)} frames; "
         "their timings include its bounce work", source=scene.name)


@contextmanager
def gl_work_clock():
    """Seconds spent in the GL_WORK calls while it is open, summed in the yielded list's item."""
    spent = [0.0]
    originals = []
    for cls, names in GL_WORK:
        for name in names:
            method = getattr(cls, name)
            originals.append((cls, name, method))

            def timed(self, *args, _method=method, **kwargs):
                start = time.perf_counter()
                try:
                    return _method(self, *args, **kwargs)
                finally:
                    spent[0] += time.perf_counter() - start
            setattr(cls, name, timed)
    try:
        yield spent
    finally:
        for cls, name, method in originals:
            setattr(cls, name, method)


def time_frames(scene, renderer, settings, kind, frames, warmup):
    """One record: the frame time (throughput of `frames` frames after `warmup`), the median
    host time of a frame, and, over the same frames rendered again with each pass timed, the
    median GPU time per pass and of a frame's passes, and the slowest frame's wall time (the
    frames that scroll a clipmap's level stand out there)."""
    path = FramePath(scene, kind)
    host, walls, measured = [], [], []
    try:
        with gl_work_clock() as work:
            for frame in range(warmup):
                path.apply(frame)
                renderer.render_frame(scene, settings)
            renderer.ctx.finish()
            start = time.perf_counter()
            for frame in range(warmup, warmup + frames):
                path.apply(frame)
                begin, busy = time.perf_counter(), work[0]
                renderer.render_frame(scene, settings)
                host.append((time.perf_counter() - begin - (work[0] - busy)) * 1000.0)
            renderer.ctx.finish()
            frame_ms = (time.perf_counter() - start) * 1000.0 / frames
        renderer.measure = True
        renderer.pass_timer.history.clear()
        for frame in range(warmup, warmup + frames):
            path.apply(frame)
            begin = time.perf_counter()
            renderer.render_frame(scene, settings)
            renderer.ctx.finish()
            walls.append((time.perf_counter() - begin) * 1000.0)
        renderer.pass_timer.flush()
        measured = list(renderer.pass_timer.history)[-frames:]
    finally:
        path.restore()
        renderer.measure = False
    passes = {name: statistics.median([timings.get(name, 0.0) for timings in measured])
              for name in PASS_ORDER if any(name in timings for timings in measured)}
    return {"frame": kind, "moves": path.subject, "total_ms": frame_ms, "host_ms": statistics.median(host),
            "gpu_ms": statistics.median([sum(timings.values()) for timings in measured]), "max_ms": max(walls),
            "passes": passes, "draw_calls": renderer.draw_calls}


def benchmark(scene, renderer, settings, grids, frames, warmup, kinds=FRAME_KINDS, reference=None):
    """Records {"scene", "grid", "frame", "width", "height", "total_ms", "passes", ...} for every
    grid and frame kind; "grid" is the resolution the renderer's levels took (a scene file's
    clipmap keeps its own whatever grid is asked: its grids are timed once)."""
    rows, timed = [], set()
    kinds = [kind for kind in kinds if kind != "animated" or scene.animations()]
    uses_voxels = MODE_TABLE[settings.mode].uses_voxels(scene_emits(scene))
    for grid in grids if uses_voxels else [settings.grid]:
        s = settings.replace(grid=grid)
        renderer.progressive = True
        settle(scene, renderer, s)
        held = (renderer.voxel_layout.n, renderer.voxel_layout.levels) if uses_voxels else None
        if held in timed:
            continue
        timed.add(held)
        unsettled = []
        for kind in kinds:
            if not settle(scene, renderer, s):  # the settled scene again, after the kind before
                unsettled.append(kind)
            record = {"scene": scene.name, "grid": renderer.voxel_layout.n if uses_voxels else None, "width": renderer.size[0],
                      "height": renderer.size[1], **time_frames(scene, renderer, s, kind, frames, warmup)}
            voxel_bytes = renderer.voxel_memory_bytes() if uses_voxels else 0
            record.update(levels=renderer.voxel_layout.levels if uses_voxels else None, voxel_count=renderer.voxel_layout.voxel_count if uses_voxels else 0,
                          voxel_bytes=voxel_bytes, voxel_bytes_per_voxel=voxel_bytes / renderer.voxel_layout.voxel_count if uses_voxels else 0.0,
                          texture_bytes=renderer.texture_memory_bytes(), peak_rss_mb=peak_rss_mb())
            rows.append(record)
        if unsettled:
            warn_unsettled(scene, unsettled)
        if reference is not None and uses_voxels:  # the accuracy of this grid, converged within one frame
            renderer.progressive = False
            renderer.render_frame(scene, s.replace(temporal_aa=False))
            for record in rows[-len(kinds):]:
                record.update(relative_errors(renderer.radiance(), reference))
    return rows


def format_table(rows):
    names = [n for n in PASS_ORDER if any(n in r["passes"] for r in rows)]
    has_error = any("rel_mae" in r for r in rows)
    header = (["grid", "frame"] + names + ["GPU", "host", "frame", "slowest", "voxel B/voxel"]
              + (["relMAE", "lum ratio"] if has_error else []))
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in rows:
        levels = f" x {r['levels']}" if r["grid"] and r["levels"] > 1 else ""
        cells = [f"{r['grid']}^3{levels}" if r["grid"] else "-", r["frame"]]
        cells += [f"{r['passes'][n]:.1f}" if n in r["passes"] else "-" for n in names]
        cells += [f"{r['gpu_ms']:.1f}", f"{r['host_ms']:.2f}", f"**{r['total_ms']:.1f}**", f"{r['max_ms']:.1f}"]
        cells += [f"{r['voxel_bytes_per_voxel']:.0f} ({r['voxel_bytes'] / 2 ** 20:.0f} MiB)" if r["grid"] else "-"]
        if has_error:
            cells += [f"{r['rel_mae']:.3f}", f"{r['luminance_ratio']:.3f}"] if "rel_mae" in r else ["", ""]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)
