"""GL calls per frame, by kind of frame and kind of call, counted by apitrace (Debian's package).

    .venv/bin/python tools/gl_calls.py scenes/sponza.json [--kinds static,light,object] [--grid 128]
        [--frames 4] [--size 256x256] [--json out.json] [--calls]

Renders the frames `vct bench` times (engine.app.bench.FramePath: the radiance settled first, as in
the viewer) under `apitrace trace`, with a debug marker (glDebugMessageInsert) before each
frame, then reads the trace back with `apitrace dump` and counts the calls between the markers.
A count does not vary from run to run the way milliseconds do on a shared machine, so it is
the figure to compare host work by. Prints, per kind of frame, the calls of its last frame by
group (program binds, uniforms, texture and buffer binds, draws, dispatches, state, buffer
writes, GPU reads, syncs); `--calls` lists every GL function with its count as well."""
import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MARKER = "vct-frame:"
# Call groups, first match wins: (group, pattern of GL function names).
GROUPS = (
    ("program binds", r"glUseProgram$"),
    ("uniforms", r"gl(Program)?Uniform"),
    ("texture binds", r"gl(ActiveTexture|BindTexture|BindTextures|BindSampler|BindImageTexture)"),
    ("buffer binds", r"glBindBuffer|glBindVertexArray|glBindFramebuffer"),
    ("draws", r"glDraw|glMultiDraw"),
    ("dispatches", r"glDispatch"),
    ("barriers", r"glMemoryBarrier"),
    ("GPU reads", r"glGetBufferSubData|glGetNamedBufferSubData|glReadPixels|glGetTex(ture)?Image|glMapBuffer|glMapNamedBuffer"
                  r"|glGetQueryObject|glGetQueryBufferObject|glClientWaitSync"),
    ("syncs", r"glFinish|glFlush|glFenceSync|glDeleteSync"),
    ("buffer writes", r"gl(Named)?Buffer(Sub)?Data|glCopy(Named)?BufferSubData|glClear(Named)?Buffer|glTex(ture)?SubImage"),
    ("queries", r"glBeginQuery|glEndQuery|glQueryCounter|glGenQueries|glCreateQueries"),
    ("state", r"."),
)


def inner(args):
    """Runs under apitrace: settle the scene, then render each kind's frames, a marker before each."""
    sys.path.insert(0, str(ROOT))
    import ctypes

    import engine
    from engine.app.bench import FramePath, settle, warn_unsettled

    gl = ctypes.CDLL("libGL.so.1")

    def mark(text):
        data = text.encode()
        gl.glDebugMessageInsert(0x824A, 0x824C, 0, 0x826B, len(data), data)  # application, other, notification

    scene = engine.load_scene(args.scene)
    width, height = (int(v) for v in args.size.split("x"))
    renderer = engine.Renderer(width, height)
    renderer.debug_groups = args.passes
    settings = renderer.settings.replace(grid=args.grid)
    renderer.progressive = True
    with renderer.ctx:
        for kind in args.kinds.split(","):
            if not settle(scene, renderer, settings):
                warn_unsettled(scene, [kind])
            path = FramePath(scene, kind)
            for frame in range(args.frames):
                path.apply(frame)
                mark(f"{MARKER}{kind}:{frame}")
                renderer.render_frame(scene, settings)
            mark(f"{MARKER}end")
            path.restore()
    renderer.close()


def group_of(name):
    return next(group for group, pattern in GROUPS if re.match(pattern, name))


def count_frames(dump_lines):
    """{kind: [(Counter of GL function -> calls, Counter of pass -> calls), one per frame]}
    from `apitrace dump` lines (the debug groups' own calls not counted)."""
    frames = collections.defaultdict(list)
    current = None
    group = "-"
    for line in dump_lines:
        match = re.match(r"\d+ (\w+)\(", line)
        if not match:
            continue
        name = match.group(1)
        if name == "glDebugMessageInsert" and MARKER in line:
            label = line.split(MARKER, 1)[1].split('"', 1)[0]
            current = None if label == "end" else (collections.Counter(), collections.Counter())
            if current is not None:
                frames[label.split(":")[0]].append(current)
        elif name == "glPushDebugGroup":
            group = line.split('message = "', 1)[1].split('"', 1)[0] if 'message = "' in line else "?"
        elif name == "glPopDebugGroup":
            group = "-"
        elif current is not None:
            current[0][name] += 1
            current[1][group] += 1
    return frames


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--kinds", default="static,light,object")
    parser.add_argument("--grid", type=int, default=128)
    parser.add_argument("--frames", type=int, default=4)
    parser.add_argument("--size", default="256x256")
    parser.add_argument("--json", help="also write {kind: {group or function: calls}} of each kind's last frame")
    parser.add_argument("--calls", action="store_true", help="list every GL function's count too")
    parser.add_argument("--passes", action="store_true",
                        help="list the calls of each pass of the last frame (the renderer's debug groups)")
    parser.add_argument("--inner", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.inner:
        inner(args)
        return
    if shutil.which("apitrace") is None:
        sys.exit("gl_calls: apitrace is missing (Debian: apt-get install apitrace)")
    with tempfile.TemporaryDirectory() as tmp:
        trace = Path(tmp) / "frames.trace"
        command = [sys.executable, str(Path(__file__).resolve()), *sys.argv[1:], "--inner"]
        subprocess.run(["apitrace", "trace", "--api", "egl", "-o", str(trace), *command], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=os.environ)
        dump = subprocess.run(["apitrace", "dump", "--color=never", str(trace)], check=True, capture_output=True, text=True)
    frames = count_frames(dump.stdout.splitlines())
    report = {}
    groups = [group for group, _ in GROUPS]
    print(f"{Path(args.scene).name}, {args.size}, grid {args.grid}: GL calls of the last of {args.frames} frames per kind")
    print("| frame | total | " + " | ".join(groups) + " |")
    print("|---|---|" + "---|" * len(groups))
    for kind, counts in frames.items():
        last, by_pass = counts[-1]
        by_group = collections.Counter()
        for name, calls in last.items():
            by_group[group_of(name)] += calls
        total = sum(last.values())
        report[kind] = {"total": total, "groups": dict(by_group), "calls": dict(last), "passes": dict(by_pass),
                        "totals_per_frame": [sum(c.values()) for c, _ in counts]}
        print(f"| {kind} | **{total}** | " + " | ".join(str(by_group.get(g, 0)) for g in groups) + " |")
    if args.passes:
        for kind, entry in report.items():
            print(f"\n{kind} by pass ('-': outside every pass): "
                  + ", ".join(f"{name} {calls}" for name, calls in sorted(entry["passes"].items(), key=lambda c: -c[1])))
    if args.calls:
        for kind, entry in report.items():
            print(f"\n{kind}: " + ", ".join(f"{name} {calls}" for name, calls in sorted(entry["calls"].items(), key=lambda c: -c[1])))
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
