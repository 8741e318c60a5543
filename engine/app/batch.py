"""Renders spread over processes and machines with Ray: `vct batch JOBS` (a JSON Lines job file,
engine/formats/job_file.py) and `vct render --frames N --workers K`.

A worker is a Ray actor: a process holding one Renderer (its own EGL context) for its whole
life, which renders the frames it is given in order, so that a job's frames reuse the voxels
and their light from one to the next as one process does. A job's frames go out in contiguous
chunks (as many as the workers, of at most CHUNK_FRAMES). On a machine with GPUs each worker
takes one (Ray's GPU resources; its EGL device the one Ray names, VCT_EGL_DEVICE); on llvmpipe
each takes an equal share of the cores and as many rasterizer threads (LP_NUM_THREADS).

Nothing is lost or done twice: every frame's files are written all or nothing as `vct render`
writes them; the frames whose files all exist are skipped, so a rerun renders what is missing;
each chunk done or failed is a line of the manifest (JSON Lines: job, frames, outputs, worker,
seconds, result, error), and so is each video written; a chunk that fails (a bad scene, a driver error, a worker that dies)
is tried once more on another worker while the others go on, and the command ends naming the
jobs that failed. Ctrl-C stops the workers and removes the files they had not finished."""
import contextlib
import glob
import json
import math
import os
import shutil
import socket
import tempfile
import time
import warnings
from collections import deque
from dataclasses import dataclass, field, replace

from ..core.errors import VctError, VctWarning, one_line
from ..formats.sequence import frame_path
from ..frame.settings import HEADLESS_SAMPLES, RenderSettings
from .frames import check_outputs

CHUNK_FRAMES = 16  # most frames of a job a worker renders in one go
TRIES = 2          # a chunk that fails is tried once more, on another worker where there is one


class BatchFailed(Exception):
    """Some jobs failed (their chunks failed twice): the message names them; exit status 1."""


def job_settings(job, source):
    """A job's RenderSettings: `vct render`'s defaults (HEADLESS_SAMPLES samples a pixel) with
    the job's own; VctError names the job file's line and the setting."""
    try:
        return RenderSettings(samples=HEADLESS_SAMPLES).replace(**job.settings).validate()
    except TypeError as exc:  # a value RenderSettings cannot take at all
        raise VctError(str(exc), source=f"{source}:{job.line}", field="settings") from None
    except VctError as exc:
        name = exc.field if exc.field and exc.field != "settings" else None
        raise VctError(exc.message, source=f"{source}:{job.line}", field=f"settings.{name}" if name else "settings") from None


def check_jobs(jobs, source):
    """Each job's settings and outputs, checked before anything renders: {job name: settings}.
    The messages name the job file's line and the job's field."""
    settings = {}
    for job in jobs:
        settings[job.name] = job_settings(job, source)
        try:
            check_outputs(job, job.frames or 1)
        except VctError as exc:
            raise VctError(exc.message if exc.source is None else f"{exc.message} ({exc.source})",
                           source=f"{source}:{job.line}", field=(exc.field or "").lstrip("-") or None) from None
    return settings


@dataclass
class Chunk:
    """Frames of a job a worker renders in one go."""

    job: object
    indices: list
    tries: int = 0
    workers_tried: set = field(default_factory=set)


@dataclass
class Outcome:
    """What a batch did: frames rendered, chunks failed, workers used."""

    frames: int = 0
    skipped_jobs: int = 0
    failed: dict = field(default_factory=dict)  # job name -> its last error line
    workers: int = 0


def frame_outputs(job, index):
    """The files of frame `index` of `job`."""
    return [frame_path(pattern, index) for pattern in (job.out, job.hdr) if pattern]


def pending_frames(job):
    """The frames of `job` whose files are not all there (a frame's files are written together)."""
    return [index for index in range(job.frames or 1) if not all(os.path.isfile(path) for path in frame_outputs(job, index))]


def chunks_of(job, indices, workers):
    """`indices` in contiguous runs, cut into about as many chunks as workers, each of at most
    CHUNK_FRAMES frames."""
    size = max(1, min(CHUNK_FRAMES, math.ceil(len(indices) / workers)))
    chunks, run = [], []
    for index in indices:
        if run and (index != run[-1] + 1 or len(run) == size):
            chunks.append(Chunk(job, run))
            run = []
        run.append(index)
    if run:
        chunks.append(Chunk(job, run))
    return chunks


class RenderWorker:
    """A worker process: one Renderer for its life, made at its first chunk (resized for a job
    of another size), and the scene of the last job it rendered, kept for its next chunk."""

    def __init__(self):
        import ray

        gpus = ray.get_gpu_ids()
        if gpus:
            os.environ["VCT_EGL_DEVICE"] = str(int(gpus[0]))
        self.renderer = None
        self.held = None  # (job, its scene, the scene's own camera)

    def where(self):
        return f"{socket.gethostname()}:{os.getpid()}"

    def render(self, job, settings, indices):
        """Render frames `indices` of `job` with `settings` and write their files; returns
        {"outputs", "seconds", "worker", "warnings"}. A VctError says why not."""
        from ..frame.renderer import Renderer
        from .frames import frame_times_of, load_lit_scene, render_frame_files

        start = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", VctWarning)
            if self.held is None or self.held[0] != job:
                scene = load_lit_scene(job)
                self.held = (job, scene, scene.camera)
            _, scene, home = self.held
            size = (job.width or home.width, job.height or home.height)
            if self.renderer is None:
                self.renderer = Renderer(*size, settings)
            elif self.renderer.size != size:
                self.renderer.resize(*size)
            self.renderer.settings = settings
            times = frame_times_of(job)
            for index in indices:
                render_frame_files(self.renderer, scene, home, job, index, times, settings)
        return {"outputs": [path for index in indices for path in frame_outputs(job, index)],
                "seconds": time.perf_counter() - start, "worker": self.where(),
                "warnings": [str(w.message) for w in caught if issubclass(w.category, VctWarning)]}


def _ray(address=None):
    """The ray module, imported for joining `address` (None: a local Ray). A cluster started by
    `ray start` checks a token (Ray 2.5x): where one is at hand (RAY_AUTH_TOKEN,
    RAY_AUTH_TOKEN_PATH or ~/.ray/auth_token) the driver presents it (Ray reads its mode as it
    is imported)."""
    if address and "RAY_AUTH_MODE" not in os.environ and (os.environ.get("RAY_AUTH_TOKEN") or os.path.isfile(
            os.environ.get("RAY_AUTH_TOKEN_PATH", os.path.expanduser("~/.ray/auth_token")))):
        os.environ["RAY_AUTH_MODE"] = "token"
    try:
        import ray
    except ImportError:
        raise VctError("needs Ray: pip install ray (on every machine of a cluster)", field="batch") from None
    return ray


def _join(ray, address):
    """Start a local Ray (`address` None) or join the cluster at `address` (HOST:PORT, or auto:
    the one this machine is part of). Ray's own lines while it connects are not shown: a
    failure is one line naming the address, at once where nothing listens there."""
    if address and address != "auto":
        host, _, port = address.rpartition(":")
        try:
            socket.create_connection((host.strip("[]") or "127.0.0.1", int(port)), timeout=5).close()
        except (OSError, ValueError) as exc:
            reason = "expected HOST:PORT" if isinstance(exc, ValueError) else exc.strerror or str(exc)
            raise VctError(f"cannot join the Ray cluster ({reason})", source=address, field="--address") from None
    with _stderr_hidden():
        try:
            ray.init(address=address, include_dashboard=False, log_to_driver=False, logging_level="ERROR")
        except Exception as exc:  # ConnectionError, RuntimeError, Ray's own: its first line says why
            with contextlib.suppress(Exception):
                ray.shutdown()
            reason = one_line(str(exc).splitlines()[0]) if str(exc) else type(exc).__name__
            if address is None:
                raise VctError(f"cannot start a local Ray ({reason})", field="batch") from None
            raise VctError(f"cannot join the Ray cluster ({reason})", source=address, field="--address") from None


@contextlib.contextmanager
def _stderr_hidden():
    """File descriptor 2 sent to /dev/null for the block (Ray's C++ core logs there)."""
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def error_line(ray, exc):
    """One line saying why a chunk failed."""
    if isinstance(exc, ray.exceptions.RayTaskError):
        cause = exc.cause if getattr(exc, "cause", None) is not None else exc
        return one_line(str(cause) if isinstance(cause, VctError) else f"{type(cause).__name__}: {cause}")
    if isinstance(exc, (ray.exceptions.RayActorError, ray.exceptions.WorkerCrashedError)):
        return "the worker died"
    return one_line(f"{type(exc).__name__}: {exc}")


class WorkerPool:
    """The Ray actors rendering the chunks, each given one at a time; a dead one is replaced."""

    def __init__(self, ray, count):
        self.ray = ray
        resources = ray.cluster_resources()
        gpus, cpus = int(resources.get("GPU", 0)), resources.get("CPU", 1.0)
        self.count = count or (gpus or max(1, int(cpus)))
        if gpus:
            options = dict(num_gpus=1, num_cpus=min(1.0, cpus / self.count))
        else:
            share = cpus / self.count
            options = dict(num_cpus=share, runtime_env={"env_vars": {"LP_NUM_THREADS": str(max(1, int(share)))}})
        self.actor_class = ray.remote(RenderWorker).options(max_concurrency=1, **options)
        self.actors = [self.actor_class.remote() for _ in range(self.count)]

    def replace(self, actor):
        """A new actor in the place of a dead one."""
        with contextlib.suppress(Exception):
            self.ray.kill(actor)
        fresh = self.actor_class.remote()
        self.actors[self.actors.index(actor)] = fresh
        return fresh

    def stop(self):
        for actor in self.actors:
            with contextlib.suppress(Exception):
                self.ray.kill(actor)


def run_jobs(jobs, workers=None, address=None, manifest=None, source="jobs"):
    """Render `jobs` on a Ray cluster (`address`; None: a local one started here) with `workers`
    workers (None: one per GPU, else one per core); each chunk done or failed is a line of
    `manifest` (a path, or None). Returns an Outcome; BatchFailed where jobs failed."""
    settings = check_jobs(jobs, source)
    ray = _ray(address)
    outcome = Outcome()
    todo, complete, frame_folders = [], [], []
    started = False
    pool = None
    try:
        for job in jobs:
            if job.video and not job.out:  # a video alone: complete once it exists; its frames go to a folder removed after
                if os.path.isfile(job.video):
                    complete.append(job)
                    continue
                job = replace(job, out=_video_frames(job))
                frame_folders.append(os.path.dirname(job.out))
            pending = pending_frames(job)
            if pending or (job.video and not os.path.isfile(job.video)):
                todo.append((job, pending))
            else:
                complete.append(job)
        with _manifest(manifest) as log:
            for job in complete:
                log({"job": job.name, "line": job.line, "result": "complete"})
            outcome.skipped_jobs = len(complete)
            if todo:
                started = not ray.is_initialized()
                if started:
                    _join(ray, address)
                pool = WorkerPool(ray, workers)
                outcome.workers = pool.count
                queue = deque(chunk for job, pending in todo for chunk in chunks_of(job, pending, pool.count))
                total = sum(len(chunk.indices) for chunk in queue)
                frames_kept = {job.name for job, _ in todo if os.path.dirname(job.out) not in frame_folders}
                _run_chunks(ray, pool, queue, settings, total, log, outcome, frames_kept)
                for job, _ in todo:
                    if job.video and job.name not in outcome.failed:
                        _write_video(job)
                        log({"job": job.name, "line": job.line, "result": "ok", "outputs": [job.video]})
    except BaseException:
        if pool is not None:
            pool.stop()
        _remove_unfinished([job for job, _ in todo])
        raise
    finally:
        for folder in frame_folders:
            shutil.rmtree(folder, ignore_errors=True)
        if started:
            ray.shutdown()
    if outcome.failed:
        named = ", ".join(f'"{name}" ({error})' for name, error in outcome.failed.items())
        raise BatchFailed(f"{len(outcome.failed)} of {len(jobs)} jobs failed: {named}")
    return outcome


def _run_chunks(ray, pool, queue, settings, total, log, outcome, frames_kept):
    """Give each idle worker the next chunk (one it has not failed) until none is left; a
    failed chunk goes back to the queue once. The manifest names the frames of the jobs in
    `frames_kept` (the others' are a video's, removed after)."""
    from ..core.progress import print_above, progress

    idle, running, warned = list(pool.actors), {}, set()
    names = {}  # actor -> "host:pid", from its first result or asked for
    with progress(total, "batch", "frame") as bar:
        while queue or running:
            for actor in list(idle):
                chunk = next((c for c in queue if actor not in c.workers_tried), None) or (queue[0] if queue and len(pool.actors) == 1 else None)
                if chunk is None:
                    continue
                queue.remove(chunk)
                idle.remove(actor)
                chunk.tries += 1
                chunk.workers_tried.add(actor)
                running[actor.render.remote(chunk.job, settings[chunk.job.name], chunk.indices)] = (chunk, actor)
            if not running:  # chunks only workers that failed them could take: give them to any
                for chunk in queue:
                    chunk.workers_tried.clear()
                continue
            (done,), _ = ray.wait(list(running), num_returns=1)
            chunk, actor = running.pop(done)
            record = {"job": chunk.job.name, "line": chunk.job.line, "frames": [chunk.indices[0], chunk.indices[-1]],
                      "try": chunk.tries}
            try:
                result = ray.get(done)
            except Exception as exc:  # the chunk's error, or its worker's death
                error = error_line(ray, exc)
                died = isinstance(exc, (ray.exceptions.RayActorError, ray.exceptions.WorkerCrashedError))
                log({**record, "result": "failed", "error": error, "worker": names.get(actor) or _name(ray, actor, died)})
                idle.append(pool.replace(actor) if died else actor)
                if chunk.tries < TRIES:
                    queue.appendleft(chunk)
                else:
                    outcome.failed[chunk.job.name] = error
                    bar.update(len(chunk.indices))
                continue
            idle.append(actor)
            names[actor] = result["worker"]
            for message in result["warnings"]:
                if message not in warned:
                    warned.add(message)
                    print_above(f"vct: warning: {message}\n")
            outputs = result["outputs"] if chunk.job.name in frames_kept else []
            log({**record, "result": "ok", "outputs": outputs, "worker": result["worker"],
                 "seconds": round(result["seconds"], 3)})
            outcome.frames += len(chunk.indices)
            bar.update(len(chunk.indices))


def _name(ray, actor, died):
    """A worker's "host:pid" where it can still say it."""
    if not died:
        with contextlib.suppress(Exception):
            return ray.get(actor.where.remote(), timeout=10)
    return "a worker that died"


@contextlib.contextmanager
def _manifest(path):
    """A function writing one JSON line (flushed) to the manifest at `path`, or nothing."""
    if path is None:
        yield lambda record: None
        return
    try:
        handle = open(path, "a", encoding="utf-8")
    except OSError as exc:
        raise VctError(f"cannot write ({exc.strerror or exc})", source=path, field="--manifest") from None
    with handle:
        def log(record):
            handle.write(json.dumps(record) + "\n")
            handle.flush()
        yield log


def _video_frames(job):
    """The PNG pattern a job that asks for a video alone renders its frames into (a folder
    removed after)."""
    folder = tempfile.mkdtemp(prefix=".vct-frames-", dir=os.path.dirname(os.path.abspath(job.video)))
    return os.path.join(folder, "f_%06d.png")


def _write_video(job):
    """The job's video from its PNG frames."""
    import numpy as np
    from PIL import Image

    from ..formats.sequence import video_file

    first = np.asarray(Image.open(frame_path(job.out, 0)).convert("RGB"))
    with video_file(job.video, (first.shape[1], first.shape[0]), job.fps) as video:
        for index in range(job.frames or 1):
            video.append(np.asarray(Image.open(frame_path(job.out, index)).convert("RGB")))


def _remove_unfinished(jobs):
    """The temporaries of the files the workers were writing when they stopped
    (engine/formats/output.py write_files names them .vct-*.tmp)."""
    folders = {os.path.dirname(os.path.abspath(frame_path(pattern, 0)))
               for job in jobs for pattern in (job.out, job.hdr) if pattern}
    for folder in folders:
        for temporary in glob.glob(os.path.join(folder, ".vct-*.tmp")):
            with contextlib.suppress(OSError):
                os.unlink(temporary)

