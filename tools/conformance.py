"""Renders a folder of glTF models (the Khronos glTF Sample Assets, fetched by the user: they are
not part of vct) as a conformance run: each model rendered alone by `vct render` in a process of
its own (framed, under the studio sky where it has no light; a time limit each), a contact sheet
of the images, and a table of what became of each model: rendered (with its warning lines) or
refused (with vct's one error line), or what went wrong past that (a crash, a time-out).

    git clone --depth 1 https://github.com/KhronosGroup/glTF-Sample-Assets
    .venv/bin/python tools/conformance.py glTF-Sample-Assets/Models --out out/conformance [--size 160]
        [--models Duck,Fox] [--timeout 120] [--mode gi]

writes out/conformance/<model>.png, contact_sheet.png and results.md / results.json. A model
folder holds its variants (glTF-Binary, glTF, glTF-Embedded, ...); the first of VARIANTS found
is rendered, or the folder's own .gltf/.glb where it has no variant folders. Exit status 0 when
every model rendered or was refused with vct's one error line, 1 where any crashed or hung."""
import argparse
import json
import subprocess
import sys
from pathlib import Path

from PIL import Image, ImageDraw

ROOT = Path(__file__).resolve().parent.parent
VARIANTS = ("glTF-Binary", "glTF", "glTF-Embedded")
LABEL_HEIGHT = 14


def model_files(folder, names=None):
    """(name, file) of each model under `folder`, sorted by name: a model folder's first
    variant of VARIANTS holding a .glb or .gltf, else a .glb or .gltf in the folder itself."""
    found = []
    for model in sorted(path for path in Path(folder).iterdir() if path.is_dir()):
        if names and model.name not in names:
            continue
        candidates = [model / variant for variant in VARIANTS] + [model]
        for place in candidates:
            files = sorted(place.glob("*.glb")) + sorted(place.glob("*.gltf")) if place.is_dir() else []
            if files:
                found.append((model.name, files[0]))
                break
    return found


def render(name, path, out, size, mode, timeout):
    """One model through `vct render`: a result row (dict)."""
    image = out / f"{name}.png"
    command = [sys.executable, "-m", "engine.app.cli", "render", str(path), "--out", str(image), "--width", str(size),
               "--height", str(size), "--mode", mode, "--quiet"]
    try:
        done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"model": name, "file": str(path), "result": "timed out", "detail": f"no image in {timeout} s", "warnings": []}
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    warnings = [line.removeprefix("vct: warning: ") for line in lines if line.startswith("vct: warning: ")]
    errors = [line.removeprefix("vct: error: ") for line in lines if line.startswith("vct: error: ")]
    if done.returncode == 0 and image.exists():
        result, detail = "rendered", ""
    elif done.returncode == 2 and len(errors) == 1 and "Traceback" not in done.stderr:
        result, detail = "refused", errors[0]
    else:
        result, detail = "crashed", f"exit {done.returncode}: " + (lines[-1] if lines else "no message")
    return {"model": name, "file": str(path), "result": result, "detail": detail, "warnings": warnings}


def contact_sheet(rows, out, size, columns=8):
    """The models' images side by side, each labelled with its name (grey where refused)."""
    count = max(len(rows), 1)
    columns = min(columns, count)
    sheet = Image.new("RGB", (columns * size, -(-count // columns) * (size + LABEL_HEIGHT)), (32, 32, 32))
    draw = ImageDraw.Draw(sheet)
    for k, row in enumerate(rows):
        x, y = (k % columns) * size, (k // columns) * (size + LABEL_HEIGHT)
        image = out / f"{row['model']}.png"
        if row["result"] == "rendered" and image.exists():
            sheet.paste(Image.open(image).convert("RGB").resize((size, size)), (x, y))
        else:
            draw.rectangle((x, y, x + size - 1, y + size - 1), fill=(80, 80, 80))
            draw.text((x + 4, y + size // 2), row["result"], fill=(255, 200, 200))
        draw.text((x + 2, y + size + 1), row["model"][:size // 6], fill=(230, 230, 230))
    sheet.save(out / "contact_sheet.png")


def table(rows):
    """results.md: a line per model, and the totals."""
    counts = {result: sum(row["result"] == result for row in rows) for result in ("rendered", "refused", "crashed", "timed out")}
    lines = ["| model | result | detail | warnings |", "|---|---|---|---|"]
    for row in rows:
        warnings = "; ".join(row["warnings"]).replace("|", "\\|")
        lines.append(f"| {row['model']} | {row['result']} | {row['detail'].replace('|', chr(92) + '|')} | {warnings} |")
    lines.append("")
    lines.append(", ".join(f"{count} {result}" for result, count in counts.items()) + f" of {len(rows)} models")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="a folder of model folders (glTF-Sample-Assets/Models)")
    parser.add_argument("--out", default=str(ROOT / "out" / "conformance"))
    parser.add_argument("--size", type=int, default=160, help="each image's side in pixels")
    parser.add_argument("--mode", default="gi")
    parser.add_argument("--models", help="comma-separated model names (default: all)")
    parser.add_argument("--timeout", type=int, default=120, help="seconds a model may take")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    models = model_files(args.folder, set(args.models.split(",")) if args.models else None)
    rows = []
    for k, (name, path) in enumerate(models, 1):
        rows.append(render(name, path, out, args.size, args.mode, args.timeout))
        if sys.stderr.isatty():
            print(f"\r{k}/{len(models)} {name[:40]:<40}", end="", file=sys.stderr, flush=True)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    contact_sheet(rows, out, args.size)
    (out / "results.md").write_text(table(rows))
    (out / "results.json").write_text(json.dumps(rows, indent=1))
    print(table(rows).splitlines()[-1])
    return 1 if any(row["result"] in ("crashed", "timed out") for row in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
