"""Screenshot file names: screenshots/<scene>-<timestamp>.png, never overwriting one."""
import re
import time
from pathlib import Path

SCREENSHOT_DIR = Path("screenshots")


def screenshot_path(scene_name, suffix="", directory=SCREENSHOT_DIR, now=None):
    """A new path under `directory` (created) for a screenshot of `scene_name`."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", scene_name).strip("_") or "scene"
    stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(now))
    path = directory / f"{stem}-{stamp}{suffix}.png"
    n = 2
    while path.exists():
        path = directory / f"{stem}-{stamp}{suffix}-{n}.png"
        n += 1
    return path
