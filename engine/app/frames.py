"""What `vct render` and the batch workers do to a frame, on options named as `vct render`'s
(an argparse namespace, or a batch Job: scene, camera, environment, out, hdr, video, orbit,
animation): the outputs checked before anything renders, the scene loaded with its sky, each
frame posed and its files written all or nothing."""
import math
import os
from pathlib import Path

from ..core.errors import VctError


def frame_times_of(options):
    """The times of the frames to render, in seconds: `options.frames` from `options.start` at
    `options.fps`, or the one `options.time` (default 0)."""
    from ..formats.sequence import frame_times

    return frame_times(options.frames, options.fps, options.start) if options.frames else [options.time or 0.0]


def pose_frame(scene, home, options, index, times):
    """Pose `scene` for frame `index` of `times` (seconds): its animations at the frame's time,
    its camera `home`, turned about the vertical as far as the frame is into the sequence where
    `options.orbit`."""
    from ..formats.sequence import orbit

    scene.camera = home
    scene.pose_at(times[index], options.animation)
    if options.orbit:
        scene.camera = orbit(scene.camera, index / len(times))


def frame_files(options, index, radiance, pixels):
    """[(path, writer)] of frame `index`'s outputs (options.out's PNG, options.hdr's radiance),
    for write_files: both or neither."""
    from ..formats.output import hdr_writer, png_writer
    from ..formats.sequence import frame_path

    outputs = [(frame_path(options.out, index), png_writer(pixels))] if options.out else []
    if options.hdr:
        outputs.insert(0, (frame_path(options.hdr, index), hdr_writer(options.hdr, radiance)))
    return outputs


def render_frame_files(renderer, scene, home, options, index, times, settings):
    """Render frame `index` (pose_frame) and write its files; returns the tone-mapped pixels.
    The first frame warns where lights light nothing the camera sees."""
    from ..formats.output import write_files

    pose_frame(scene, home, options, index, times)
    radiance = renderer.render(scene)
    pixels = renderer.tonemapped()
    check_finite(radiance, options.scene)
    if index == 0:
        warn_if_black(scene, radiance, settings, options.scene)
    write_files(frame_files(options, index, radiance, pixels))
    return pixels


def check_writable(path, flag):
    """Refuse an output path that cannot be written, before rendering anything."""
    from ..formats.output import check_target

    path = Path(path)
    try:
        check_target(path)
    except IsADirectoryError:
        raise VctError("is a directory", source=path, field=flag) from None
    except OSError as exc:  # e.g. a name too long for the file system
        raise VctError(f"cannot write ({exc.strerror or exc})", source=path, field=flag) from None
    if not path.parent.is_dir():
        raise VctError("directory does not exist", source=path, field=flag)
    if not os.access(path.parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise VctError("not writable", source=path, field=flag)


def load_lit_scene(args):
    """The scene of the command line with its --environment, if any; one warning line where
    nothing can light it."""
    import numpy as np

    from ..scene.emitters import scene_emits
    from ..core.errors import warn
    from ..formats.input_files import InputFiles, os_problem, read_radiance_map
    from ..core.limits import MAX_EMISSION
    from ..scene.model import Environment, studio_environment
    from ..formats.scene_file import load_scene

    scene = load_scene(args.scene, camera=args.camera)
    if args.environment == "none":
        scene.environment = None
    elif args.environment:
        parts = args.environment.split(",")
        try:
            radiance = [float(part) for part in parts] if len(parts) == 3 else None
        except ValueError:
            radiance = None
        if radiance is not None:
            if not all(math.isfinite(v) and 0 <= v <= MAX_EMISSION for v in radiance):
                raise VctError(f"a sky's radiance must be within 0..{MAX_EMISSION:g}, got {args.environment}",
                               field="--environment")
            scene.environment = Environment(radiance=np.array(radiance))
        else:
            inputs = InputFiles()
            try:
                image = read_radiance_map(args.environment, inputs)
            except (OSError, ValueError) as exc:
                raise VctError(os_problem(exc), source=args.environment, field="--environment") from None
            scene.environment = Environment(image=image, name=f"{args.environment}: --environment")
            scene.files += tuple(inputs.paths)
    if not scene.lights() and not scene_emits(scene) and scene.environment is None:
        if args.environment == "none":
            warn("no light: the scene has no lights, no emissive surfaces and no environment, so the image is black",
                 source=args.scene)
        else:
            scene.environment = studio_environment()
            warn("no light in the scene: shown under the studio sky (--environment none keeps it black)", source=args.scene)
    return scene


def check_finite(radiance, scene):
    """Refuse to write an image holding NaN or infinite values."""
    import numpy as np

    bad = int(np.count_nonzero(~np.isfinite(radiance)))
    if bad:
        raise VctError(f"the render holds {bad} NaN or infinite values (of {radiance.size}); nothing written",
                       source=scene, field="radiance")


def warn_if_black(scene, radiance, settings, source):
    """One warning line where lights exist but a lit image came out black."""
    from ..core.errors import warn

    if settings.shown.terms and "ao" not in settings.shown.terms and scene.lights() and not radiance.any():
        names = ", ".join(f'"{node.name}"' for node, _ in scene.lights())
        warn(f"the image is black: the light of {names} reaches nothing the camera sees (enclosed by geometry, or "
             "pointing away?)", source=source)


def check_outputs(args, frames):
    """The output names of `vct render`, checked before anything is rendered: writable, of a
    known kind, patterns where there are several frames, none the same as another."""
    from ..formats.output import HDR_WRITERS
    from ..formats.sequence import VIDEO_SUFFIXES, check_pattern, frame_path

    if not args.out and not args.video:
        raise VctError("give --out (PNG frames) or --video (an .mp4), or both", field="--out")
    named = [(path, flag) for path, flag in ((args.out, "--out"), (args.hdr, "--hdr")) if path]
    for path, flag in named:
        check_pattern(path, flag, frames)
        check_writable(frame_path(path, 0), flag)
    if args.hdr and Path(frame_path(args.hdr, 0)).suffix.lower() not in HDR_WRITERS:
        raise VctError(f"must end in {' or '.join(HDR_WRITERS)}", source=args.hdr, field="--hdr")
    if args.video:
        check_writable(args.video, "--video")
        if Path(args.video).suffix.lower() not in VIDEO_SUFFIXES:
            raise VctError(f"must end in {' or '.join(VIDEO_SUFFIXES)}", source=args.video, field="--video")
        named.append((args.video, "--video"))
    resolved = {}
    for path, flag in named:
        other = resolved.setdefault(Path(frame_path(path, 0)).resolve(), flag)
        if other != flag:
            raise VctError(f"must differ from {other}", source=path, field=flag)
    return named
