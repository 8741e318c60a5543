"""Batch job files (`vct batch`): JSON Lines, one render a line, each what `vct render` takes as
its options (scene, outputs, a time or a range of frames, camera, size, the render settings).
The file is read and checked whole before anything renders: a fault is one error naming the
file, the line and the field. Relative paths are the job file's folder's; every worker of a
cluster reads and writes them at the same paths (a shared file system)."""
import json
import os
from dataclasses import dataclass, field

import jsonschema

from ..core.errors import VctError
from ..core.limits import MAX_IMAGE_SIDE, MAX_MAGNITUDE
from .input_files import os_problem, read_regular_file
from .scene_schema import first_fault, object_schema

MAX_JOB_FILE_BYTES = 64 * 2 ** 20
MAX_JOBS = 100000
MAX_JOB_FRAMES = 100000  # of one job, as `vct render --frames`
PATH_FIELDS = ("scene", "out", "hdr", "video", "environment")


def _text(description):
    return {"type": "string", "minLength": 1, "maxLength": 4096, "description": description}


def _whole(description, minimum, maximum):
    return {"type": "integer", "minimum": minimum, "maximum": maximum, "description": description}


JOB_SCHEMA = object_schema("One render of a batch, a line of a JSON Lines job file: the options of `vct render`", {
    "name": {"type": "string", "minLength": 1, "maxLength": 200,
             "description": "what the manifest and the messages call the job (default: line N)"},
    "scene": _text("scene file: JSON, or a model (.glb .gltf .obj .ply .stl .off) as a whole scene"),
    "out": _text("PNG output; a pattern with %d (f_%04d.png) where the job has several frames"),
    "hdr": _text("linear radiance output, .npy or .exr; a pattern as out"),
    "video": _text("an H.264 video of the job's frames, .mp4"),
    "time": {"type": "number", "minimum": -MAX_MAGNITUDE, "maximum": MAX_MAGNITUDE,
             "description": "the scene's animations at this time, seconds (default 0)"},
    "frames": _whole("a sequence of this many frames, frame i at start + i / fps", 1, MAX_JOB_FRAMES),
    "fps": {"type": "number", "exclusiveMinimum": 0, "maximum": MAX_MAGNITUDE, "description": "frames a second (default 30)"},
    "start": {"type": "number", "minimum": -MAX_MAGNITUDE, "maximum": MAX_MAGNITUDE,
              "description": "time of the first frame, seconds (default 0)"},
    "orbit": {"type": "boolean", "description": "turn the camera once about the vertical through its look-at point"},
    "animation": _text("play only this animation of the scene's glTF files"),
    "camera": _text("the camera of this name (a glTF file's)"),
    "environment": _text("the sky: a radiance map, R,G,B, or none"),
    "width": _whole("image width (default: the scene camera's)", 1, MAX_IMAGE_SIDE),
    "height": _whole("image height (default: the scene camera's)", 1, MAX_IMAGE_SIDE),
    "settings": {"type": "object", "description": "render settings by name (engine.RenderSettings: mode, grid, samples, ...)"},
}, required=("scene",))
_VALIDATOR = jsonschema.Draft202012Validator(JOB_SCHEMA)


@dataclass(frozen=True)
class Job:
    """One render in `vct render`'s terms: its options by their names (paths absolute)."""

    name: str
    line: int  # its line in the job file
    scene: str
    out: str = None
    hdr: str = None
    video: str = None
    time: float = None
    frames: int = None
    fps: float = 30.0
    start: float = 0.0
    orbit: bool = False
    animation: str = None
    camera: str = None
    environment: str = None
    width: int = None
    height: int = None
    settings: dict = field(default_factory=dict)


def load_jobs(path):
    """The jobs of the JSON Lines file at `path` (blank lines skipped); VctError names the line
    and field of the first fault."""
    try:
        data = read_regular_file(path, MAX_JOB_FILE_BYTES)
    except (OSError, ValueError) as exc:
        raise VctError(f"cannot read job file ({os_problem(exc)})", source=path) from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise VctError(f"not UTF-8 text (byte {exc.start})", source=path) from None
    folder = os.path.dirname(os.path.abspath(path))
    jobs, names = [], {}
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        where = f"{path}:{number}"
        if len(jobs) == MAX_JOBS:
            raise VctError(f"more than {MAX_JOBS} jobs", source=where)
        try:
            document = json.loads(line, parse_constant=_refuse_constant)
        except (json.JSONDecodeError, ValueError) as exc:
            raise VctError(f"malformed JSON: {getattr(exc, 'msg', exc)}", source=where) from None
        fault = first_fault(_VALIDATOR, document)
        if fault is not None:
            raise VctError(fault[1], source=where, field=fault[0] or None)
        if "time" in document and "frames" in document:
            raise VctError("give time or frames, not both", source=where, field="time")
        document = {key: os.path.join(folder, value) if key in PATH_FIELDS and not _special(key, value) else value
                    for key, value in document.items()}
        if not os.path.isfile(document["scene"]):
            raise VctError("file not found", source=where, field="scene")
        if "out" not in document and "video" not in document:
            raise VctError("give out (PNG frames) or video (an .mp4), or both", source=where, field="out")
        name = document.pop("name", f"line {number}")
        if name in names:
            raise VctError(f'the name "{name}" is line {names[name]}\'s too', source=where, field="name")
        names[name] = number
        jobs.append(Job(name=name, line=number, **document))
    if not jobs:
        raise VctError("no jobs (one JSON object a line)", source=path)
    return jobs


def _special(key, value):
    """Whether a path field's value is not a path: the environment's R,G,B or none."""
    return key == "environment" and (value == "none" or value.count(",") == 2)


def _refuse_constant(token):
    raise ValueError(f"{token} is not a number")
