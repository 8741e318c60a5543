"""`vct`: render, batch, view and benchmark scenes. A thin layer over engine.Renderer.

Exit status: 0 when the command did its work (its files are written; a closed or full stdout
loses only the report printed there), 2 after one line `vct: error: ...` on stderr (nothing
written), 1 where jobs of a batch failed (the line names them; the others' files are
written), 128 + the signal's number after SIGINT (130), SIGHUP (129) or SIGTERM (143), which
remove the temporary files of outputs not yet complete."""
import argparse
import contextlib
import math
import os
import signal
import sys
import threading
import time
import warnings
from pathlib import Path

from ..core.constants import MAX_VOXEL_LEVELS
from ..core.errors import VctError, VctWarning, one_line
from ..frame.settings import DIFFUSE_CONE_SETS, HEADLESS_SAMPLES, MAX_BOUNCES, MAX_EXPOSURE, MAX_SAMPLES, MODES, TONEMAPS, RenderSettings


class OneLineErrorParser(argparse.ArgumentParser):
    """Usage errors as one line like every other error (`vct: error: ...`, exit code 2), named
    by the program: the first word of `prog` (`vct render` -> `vct`)."""

    def error(self, message):
        self.exit(2, f"{self.prog.split()[0]}: error: {one_line(message)} (see `{self.prog} --help`)\n")


def _finite_float(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text!r}")
    return value


def _whole_number(minimum, maximum=None):
    """argparse type: an int of at least `minimum` (and at most `maximum`)."""
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be at least {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(f"must be at most {maximum}, got {value}")
        return value
    return parse


positive_int = _whole_number(1)


def _positive_float(text):
    value = _finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be greater than 0, got {text!r}")
    return value


def _add_animation_argument(parser):
    parser.add_argument("--animation", metavar="NAME",
                        help="play only this animation of the scene's glTF files (default: all of them together)")


def _add_quiet_argument(parser):
    parser.add_argument("--quiet", action="store_true", help="no progress bar or progress summary line")
_nonnegative_int = _whole_number(0)
# Upper bounds of the frame counts: every loop a command line controls is bounded.
MAX_VIEW_FRAMES = 10000
MAX_BENCH_FRAMES = 1000
MAX_FRAMES = 100000  # of a `vct render --frames` sequence
MAX_WORKERS = 4096   # of a batch


def _add_settings_arguments(parser, default_mode="gi"):
    d = RenderSettings()
    parser.add_argument("--width", type=positive_int, help="image width (default: the scene camera's)")
    parser.add_argument("--height", type=positive_int, help="image height (default: the scene camera's)")
    parser.add_argument("--mode", choices=MODES, default=default_mode,
                        help=f"what to show (default {default_mode}): gi = direct + diffuse and specular indirect + emission; "
                             "direct; indirect (diffuse); specular; ao; albedo/normal/depth (G-buffer); "
                             "voxels/voxel-normals/voxel-albedo (the voxel grid at --mip)")
    parser.add_argument("--grid", type=int, default=d.grid, help=f"voxels per side: 16, 32, 64, 128 or 256 (default {d.grid})")
    parser.add_argument("--clipmap", type=_whole_number(0, MAX_VOXEL_LEVELS), default=d.clipmap_levels, metavar="LEVELS",
                        help="voxelize into this many levels of --grid^3 centred on the camera, each twice as large as "
                             "the one inside it, the coarsest twice the scene's size, instead of the scene file's "
                             f"voxel_region (at most {MAX_VOXEL_LEVELS}; 0: one grid over the scene even where the file "
                             "gives a clipmap; default: the file's clipmap, else one grid)")
    parser.add_argument("--bounces", type=_nonnegative_int, default=d.bounces,
                        help=f"diffuse bounces: 1 = direct + one indirect bounce, K = K bounces (at most {MAX_BOUNCES}), "
                             "0 = iterate until converged, which also stops after at most "
                             f"{MAX_BOUNCES} (default 0)")
    parser.add_argument("--bounce-interleave", type=positive_int, default=d.bounce_interleave,
                        help="viewer and bench with --bounces 0: each frame 1 in K of the voxels gathers light again "
                             "(and takes a moved light's direct light), the others keep theirs "
                             f"(default {d.bounce_interleave}; 1 = all)")
    parser.add_argument("--mip", type=_nonnegative_int, default=d.voxel_mip, help="mip level for the voxel views (default 0)")
    parser.add_argument("--level", type=_nonnegative_int, default=d.voxel_level,
                        help="clipmap level for the voxel views (default 0, the finest)")
    parser.add_argument("--cone-step", type=_finite_float, default=d.cone_step,
                        help=f"cone march step as a fraction of the cone diameter (default {d.cone_step})")
    parser.add_argument("--cone-offset", type=_finite_float, default=d.cone_offset,
                        help=f"cone start offset along the normal, in voxels (default {d.cone_offset})")
    parser.add_argument("--diffuse-cones", choices=DIFFUSE_CONE_SETS, default=d.diffuse_cones,
                        help="the diffuse and AO cones: tiled = the lecture's six, each traced as seven narrower "
                             "ones, nearer a path tracer where wide cones mix near and far surfaces, at about 14x the "
                             "gather's cost (the viewer converges with the six and refines with the tiled set once the "
                             f"scene rests); six = the lecture's six (default {d.diffuse_cones})")
    parser.add_argument("--ao-distance", type=_finite_float, default=d.ao_distance,
                        help=f"AO cones stop after this distance in scene units (default {d.ao_distance})")
    parser.add_argument("--no-direct", action="store_true", help="gi: leave out direct light and emission")
    parser.add_argument("--no-diffuse", action="store_true", help="gi: leave out diffuse indirect light")
    parser.add_argument("--no-specular", action="store_true", help="gi: leave out specular indirect light")
    parser.add_argument("--exposure", type=_finite_float, default=d.exposure, help=f"exposure multiplier before tone mapping, at most {MAX_EXPOSURE:g} (default {d.exposure})")
    parser.add_argument("--shaders", help="GLSL directory to use instead of the project's glsl/ (for shader work)")
    parser.add_argument("--camera", metavar="NAME",
                        help="render from the camera node of this name (a glTF camera) instead of the scene's camera")
    parser.add_argument("--environment", metavar="FILE|R,G,B|none",
                        help="light from beyond the scene, instead of the scene file's: an equirectangular map of "
                             "linear radiance (.exr or .hdr), a uniform sky's radiance R,G,B in W/(m^2 sr), or none "
                             "(a scene with no light at all is otherwise shown under a grey studio sky)")
    parser.add_argument("--tonemap", choices=TONEMAPS, default=d.tonemap, help=f"tone curve for the PNG (default {d.tonemap})")


def _add_temporal_argument(parser, help):
    parser.add_argument("--no-temporal-aa", dest="temporal_aa", action="store_false", help=help)


def settings_from_args(args):
    return RenderSettings(mode=args.mode, grid=args.grid, clipmap_levels=args.clipmap, bounces=args.bounces,
                          bounce_interleave=args.bounce_interleave, voxel_mip=args.mip, voxel_level=args.level,
                          cone_step=args.cone_step, cone_offset=args.cone_offset, diffuse_cones=args.diffuse_cones,
                          ao_distance=args.ao_distance,
                          direct=not args.no_direct, indirect_diffuse=not args.no_diffuse,
                          indirect_specular=not args.no_specular, exposure=args.exposure,
                          tonemap=args.tonemap, samples=getattr(args, "samples", 1),
                          temporal_aa=getattr(args, "temporal_aa", False)).validate()


def build_parser():
    parser = OneLineErrorParser(prog="vct", description="Voxel cone tracing renderer (OpenGL 4.5 via moderngl).")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    render = commands.add_parser("render", help="render a scene headless to PNG (and linear HDR .npy or .exr)",
                                 description="Render a scene headless (EGL) to a tone-mapped PNG and optionally "
                                             "linear float32 radiance (H, W, 3), row 0 at the top, as .npy or OpenEXR.")
    render.add_argument("scene", help="scene file: JSON, or a model (.glb .gltf .obj .ply .stl .off) as a whole scene")
    render.add_argument("--out", help="output PNG path; with --frames a pattern the frame's number fills (f_%%04d.png)")
    render.add_argument("--hdr", help="also write linear radiance before tone mapping: FILE.npy (numpy float32) "
                                      "or FILE.exr (OpenEXR, float32 RGB); with --frames a pattern as --out")
    when = render.add_mutually_exclusive_group()
    when.add_argument("--time", type=_finite_float, help="render the scene's animations at this time in seconds "
                                                         "(default 0)")
    when.add_argument("--frames", type=_whole_number(1, MAX_FRAMES),
                      help=f"render a sequence of this many frames (at most {MAX_FRAMES}), frame i at "
                           "--start + i / --fps")
    render.add_argument("--fps", type=_positive_float, default=30.0, help="frames per second of a sequence (default 30)")
    render.add_argument("--start", type=_finite_float, default=0.0, help="time of a sequence's first frame (default 0)")
    render.add_argument("--video", help="also write the frames as an H.264 video, FILE.mp4")
    render.add_argument("--orbit", action="store_true",
                        help="turn the camera once about the vertical axis through its look-at point over the frames")
    render.add_argument("--workers", type=_whole_number(1, MAX_WORKERS),
                        help="render the --frames on this many worker processes of a local Ray cluster (vct batch)")
    render.add_argument("--samples", type=_whole_number(1, MAX_SAMPLES), default=HEADLESS_SAMPLES,
                        help="anti-aliasing: jittered samples a pixel averages, a box filter; the voxels and "
                             f"their light are computed once for all of them (default {HEADLESS_SAMPLES}; 1: the pixel "
                             "centres, no anti-aliasing)")
    _add_animation_argument(render)
    _add_quiet_argument(render)
    _add_settings_arguments(render)

    batch = commands.add_parser("batch", help="render a job file's renders on Ray workers, here or on a cluster",
                                description="Render the jobs of a JSON Lines file (one `vct render` a line: scene, out, hdr, "
                                            "video, time or frames/fps/start, orbit, animation, camera, environment, width, "
                                            "height, settings) on Ray workers: a local Ray by default, or a cluster joined by "
                                            "--address. Frames whose files exist are skipped; each chunk done or failed is "
                                            "a line of the manifest.")
    batch.add_argument("jobs", help="the job file: JSON Lines, one render a line")
    batch.add_argument("--workers", type=_whole_number(1, MAX_WORKERS),
                       help="worker processes (default: one per GPU of the cluster, else one per core)")
    batch.add_argument("--address", help="join this Ray cluster (HOST:PORT, as `ray start --head` prints) instead of "
                                         "starting a local one")
    batch.add_argument("--manifest", help="the manifest, JSON Lines appended to (default: JOBS with .manifest.jsonl)")
    _add_quiet_argument(batch)

    view = commands.add_parser("view", help="open the interactive viewer",
                               description="Interactive viewer: fly camera, overlay, scene graph and inspector, "
                                           "GLSL hot reload. Keys: WASD/QE move, drag to look, scroll for speed, "
                                           "R reset camera, V vsync, F12/PrtScrn screenshot, Esc quit.")
    view.add_argument("scene", help="scene file: JSON, or a model (.glb .gltf .obj .ply .stl .off) as a whole scene")
    view.add_argument("--frames", type=_whole_number(1, MAX_VIEW_FRAMES),
                      help=f"render this many frames (at most {MAX_VIEW_FRAMES}), then exit")
    view.add_argument("--screenshot", help="with --frames: save the last frame (without panels) to this PNG")
    view.add_argument("--no-panels", action="store_true", help="start with the panels hidden")
    _add_temporal_argument(view, "start with temporal anti-aliasing off (a toggle in the Renderer panel)")
    _add_animation_argument(view)
    _add_settings_arguments(view)

    bench = commands.add_parser("bench", help="time static, camera, light, object and animated frames and their passes",
                                description="Time the kinds of frame the viewer renders once the bounces settled, for "
                                            "each grid size: static (the camera turns), camera (it flies at walking "
                                            "speed), light (the scene's first light moves), object (its smallest "
                                            "object moves) and, for a scene with animations, animated (they play, "
                                            "1/30 s a frame). Per kind: the frame time (throughput over the frames, "
                                            "one finish at the end), the host time of a frame (its Python and the GL "
                                            "calls that only record work), and the median GPU time of each pass "
                                            "(GL timer queries; on llvmpipe, the wall clock around a finish).")
    bench.add_argument("scene", help="scene file: JSON, or a model (.glb .gltf .obj .ply .stl .off) as a whole scene")
    bench.add_argument("--frames", type=_whole_number(1, MAX_BENCH_FRAMES), default=10,
                       help=f"timed frames per kind and grid, at most {MAX_BENCH_FRAMES} (default 10)")
    bench.add_argument("--warmup", type=_whole_number(0, MAX_BENCH_FRAMES), default=3,
                       help=f"untimed frames first, at most {MAX_BENCH_FRAMES} (default 3)")
    bench.add_argument("--grids", default="16,32,64,128,256",
                       help="comma-separated grid sizes, each at most once (default 16,32,64,128,256)")
    bench.add_argument("--json", help="also write the records as a JSON list to this file")
    bench.add_argument("--reference", help="a reference radiance .npy to report the error of each grid's converged image against")
    _add_temporal_argument(bench, "time the frames without temporal anti-aliasing (the viewer's default is on)")
    _add_quiet_argument(bench)
    _add_settings_arguments(bench)
    return parser


class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds the command as KeyboardInterrupt does for SIGINT,
    so every temporary file is removed on the way out."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def _signals_unwind():
    """While a command runs in the main thread, SIGTERM and SIGHUP raise Terminated; a signal
    whose handler was installed outside Python (a tracer, an embedding host: Python cannot put
    it back) is left to it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise Terminated(signum)

    previous = {number: signal.signal(number, handler) for number in (signal.SIGTERM, signal.SIGHUP)
                if signal.getsignal(number) is not None}
    try:
        yield
    finally:
        for number, action in previous.items():
            signal.signal(number, action)


def main(argv=None):
    """The `vct` command. Warnings of the libraries it uses (numpy's floating-point ones
    among them) are not printed: an error is its one line, a success prints its report."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run(argv)


def run(argv=None):
    """main without its filter of the libraries' warnings (the tests run it with warnings as
    errors). VctWarnings print as one line each, `vct: warning: ...`, on stderr."""
    args = build_parser().parse_args(argv)
    commands = {"render": render_command, "batch": batch_command, "view": view_command, "bench": bench_command}
    from ..core.progress import set_quiet

    set_quiet(getattr(args, "quiet", False))
    try:
        with _signals_unwind(), warnings.catch_warnings():
            warnings.simplefilter("always", VctWarning)
            warnings.showwarning = _print_warning
            return commands[args.command](args)
    except VctError as exc:
        with contextlib.suppress(OSError):  # a closed or full stderr: the exit status still says it
            print(f"vct: error: {exc}", file=sys.stderr, flush=True)
        return 2
    except KeyboardInterrupt:
        return 128 + signal.SIGINT
    except Terminated as exc:
        return 128 + exc.signum


def _print_warning(message, category, filename, lineno, file=None, line=None):
    """warnings.showwarning for the command: a VctWarning as its one line; any other warning
    that a filter lets through in Python's own words."""
    from ..core.progress import print_above

    text = f"vct: warning: {message}\n" if issubclass(category, VctWarning) else \
        warnings.formatwarning(message, category, filename, lineno, line)
    with contextlib.suppress(OSError):
        print_above(text)  # a progress bar on the terminal stays below the warning
        sys.stderr.flush()


def report(text):
    """Print a line of the command's report on stdout. Once stdout is closed or full (a pipe
    whose reader left, /dev/full), the rest of the report goes to /dev/null: the command
    carries on, and its exit status is that of its work."""
    try:
        print(one_line(text), flush=True)
    except OSError:
        with contextlib.suppress(OSError, ValueError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def shader_root(args):
    from ..gpu.shaders import GLSL_ROOT

    if not args.shaders:
        return GLSL_ROOT
    root = Path(args.shaders)
    if not os.path.isdir(root):
        raise VctError("not a directory", source=root, field="--shaders")
    return root


def check_not_an_input(path, flag, inputs):
    """Refuse an output path that is one of the files the command reads (`inputs`: the scene,
    its meshes and images, its shaders, a reference), found by identity (links included)."""
    try:
        output = os.stat(path)
    except (OSError, ValueError):
        return
    for source in inputs:
        try:
            read = os.stat(source)
        except OSError:
            continue
        if (read.st_dev, read.st_ino) == (output.st_dev, output.st_ino):
            raise VctError(f"is a file this command reads ({source}); nothing written", source=path, field=flag)


def open_renderer(width, height, settings, args):
    from ..frame.renderer import Renderer

    return Renderer(width, height, settings, glsl_root=shader_root(args))


def check_animation(scene, args):
    """Refuse an --animation the scene does not have, before anything is rendered."""
    scene.played(args.animation, field="--animation", source=args.scene)


def render_command(args):
    from ..formats.output import HDR_WRITERS
    from ..core.progress import progress
    from ..formats.sequence import describe_times, frame_path, video_file
    from .frames import check_outputs, frame_times_of, load_lit_scene, render_frame_files

    frames = args.frames or 1
    named = check_outputs(args, frames)
    settings = settings_from_args(args)
    scene = load_lit_scene(args)
    times = frame_times_of(args)
    check_animation(scene, args)
    width = args.width or scene.camera.width
    height = args.height or scene.camera.height
    if args.workers:
        return render_on_workers(args, settings, named, times, (width, height))
    home = scene.camera
    with open_renderer(width, height, settings, args) as renderer:
        for path, flag in named:
            check_not_an_input(frame_path(path, 0), flag, renderer.inputs(scene))
        if args.out and Path(frame_path(args.out, 0)).suffix.lower() != ".png":  # an output that is an input is named first
            raise VctError(f"must end in .png (linear radiance: --hdr FILE{' or FILE'.join(HDR_WRITERS)})", source=args.out, field="--out")
        video = video_file(args.video, (width, height), args.fps) if args.video else contextlib.nullcontext()
        with video as video, progress(frames, "render", "frame", summary=frames > 1) as bar:
            for index in range(frames):
                pixels = render_frame_files(renderer, scene, home, args, index, times, settings)
                if args.video:
                    video.append(pixels)
                bar.update()
    written = " and ".join(path if flag == "--video" else frame_path(path, 0) if frames == 1 else path for path, flag in named)
    when = f", {describe_times(times)}" if scene.animations() or frames > 1 else ""
    report(f"wrote {f'{frames} frames: ' if frames > 1 else ''}{written} ({width}x{height}, mode {settings.mode}{when})")
    return 0


def render_on_workers(args, settings, named, times, size):
    """`vct render --frames N --workers K`: the sequence as one batch job (engine/app/batch.py)."""
    from dataclasses import asdict

    from ..formats.job_file import Job
    from ..formats.sequence import describe_times
    from .batch import run_jobs

    job = Job(name=os.path.basename(args.scene), line=0, scene=args.scene, out=args.out, hdr=args.hdr, video=args.video,
              time=args.time, frames=args.frames, fps=args.fps, start=args.start, orbit=args.orbit, animation=args.animation,
              camera=args.camera, environment=args.environment, width=size[0], height=size[1],
              settings=asdict(settings))
    outcome = run_jobs([job], workers=args.workers, address=None, manifest=None)
    written = " and ".join(path for path, _ in named)
    report(f"wrote {len(times)} frames: {written} ({size[0]}x{size[1]}, mode {settings.mode}, {describe_times(times)}, "
           f"{outcome.workers} worker{'s' if outcome.workers != 1 else ''})")
    return 0


def batch_command(args):
    from ..formats.job_file import load_jobs
    from .batch import BatchFailed, run_jobs
    from .frames import check_writable

    jobs = load_jobs(args.jobs)
    manifest = args.manifest or str(Path(args.jobs).with_suffix(".manifest.jsonl"))
    check_writable(manifest, "--manifest")
    try:
        outcome = run_jobs(jobs, workers=args.workers, address=args.address, manifest=manifest, source=args.jobs)
    except BatchFailed as exc:
        with contextlib.suppress(OSError):
            print(f"vct: error: {one_line(str(exc))}; see {manifest}", file=sys.stderr, flush=True)
        return 1
    complete = f"{outcome.skipped_jobs} of {len(jobs)} jobs complete before"
    if outcome.workers:
        frames = f"{outcome.frames} frame{'s' if outcome.frames != 1 else ''}"
        report(f"rendered {frames} on {outcome.workers} workers ({complete}); manifest {manifest}")
    else:
        report(f"nothing to render ({complete}); manifest {manifest}")
    return 0


def view_command(args):
    from .frames import check_writable, load_lit_scene
    from .viewer.app import Viewer

    if args.screenshot:
        check_writable(args.screenshot, "--screenshot")
    settings = settings_from_args(args)
    scene = load_lit_scene(args)
    check_animation(scene, args)
    size = (args.width or scene.camera.width, args.height or scene.camera.height)
    viewer = Viewer(scene, settings, size, glsl_root=shader_root(args), show_panels=not args.no_panels,
                    vsync=args.frames is None, animation=args.animation)
    with viewer:
        if args.screenshot:
            check_not_an_input(args.screenshot, "--screenshot", viewer.renderer.inputs(scene))
        viewer.run(args.frames)
        if args.screenshot:
            path = viewer.save_screenshot(args.screenshot)
            report(f"wrote {path} ({viewer.renderer.size[0]}x{viewer.renderer.size[1]}, mode {viewer.settings.mode}, "
                   f"{viewer.frames.frames} frames)")
    return 0


def load_reference(path, shape):
    """A reference radiance .npy of the given shape, as float64; anything else (not a regular
    file, an .npz archive, another shape, NaN) is an error naming --reference."""
    import io

    import numpy as np

    from ..formats.input_files import os_problem, read_regular_file
    from ..core.limits import MAX_REFERENCE_BYTES

    def fail(message):
        raise VctError(message, source=path, field="--reference")

    try:
        data = np.load(io.BytesIO(read_regular_file(path, MAX_REFERENCE_BYTES)), allow_pickle=False)
    except (OSError, ValueError, EOFError) as exc:
        fail(f"cannot read reference ({os_problem(exc)})")
    if not isinstance(data, np.ndarray):
        data.close()
        fail("not a .npy array (an .npz archive?)")
    if data.shape != shape:
        fail(f"shape {data.shape} does not match the image {shape}")
    if data.dtype.kind not in "fiu":
        fail(f"must hold numbers, not {data.dtype}")
    reference = np.asarray(data, np.float64)
    if not np.all(np.isfinite(reference)):
        fail("holds NaN or infinite values")
    if reference.sum() <= 0:
        fail("holds no light (errors are relative to its sum)")
    return reference


def parse_grids(text):
    try:
        grids = [int(g) for g in text.split(",") if g.strip()]
    except ValueError:
        raise VctError(f"expected comma-separated whole numbers, got {text!r}", field="--grids") from None
    if not grids or len(set(grids)) != len(grids):
        raise VctError(f"expected each grid size once, got {text!r}", field="--grids")
    return grids


def bench_command(args):
    import json

    from .bench import benchmark, format_table, peak_rss_mb
    from .frames import check_writable, load_lit_scene
    from ..gpu.context import renderer_name
    from ..formats.output import write_files

    grids = parse_grids(args.grids)
    settings = settings_from_args(args)
    for grid in grids:
        settings.replace(grid=grid).validate()
    if args.json:
        check_writable(args.json, "--json")
    start = time.perf_counter()
    scene = load_lit_scene(args)
    load_s, load_rss_mb = time.perf_counter() - start, peak_rss_mb()
    width, height = args.width or scene.camera.width, args.height or scene.camera.height
    reference = load_reference(args.reference, (height, width, 3)) if args.reference else None
    with open_renderer(width, height, settings, args) as renderer:
        if args.json:
            check_not_an_input(args.json, "--json", renderer.inputs(scene) + ([args.reference] if args.reference else []))
        device = renderer_name(renderer.ctx)
        report(f"{scene.name}: loaded in {load_s:.2f} s, peak RSS {load_rss_mb:.0f} MB; {width}x{height}, mode "
               f"{settings.mode}, {args.frames} frames after {args.warmup} warm-up per kind, on {device}; ms: GPU per "
               f"pass (median), host and frame (throughput) of a frame, slowest frame")
        rows = benchmark(scene, renderer, settings, grids, args.frames, args.warmup, reference=reference)
    for row in rows:
        row.update(load_s=load_s, load_peak_rss_mb=load_rss_mb)
    for line in format_table(rows).splitlines():
        report(line)
    moved = {row["frame"]: row["moves"] for row in rows}
    report("moving: " + ", ".join(f"{kind}: {subject}" for kind, subject in moved.items()))
    if args.json:
        for row in rows:
            row["device"] = device
        write_files([(args.json, lambda f: f.write(json.dumps(rows, indent=2).encode()))])
        report(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
