"""Writing results: tone-mapped PNG and linear float32 .npy, each written atomically (to a
temporary name in the target directory, then moved), so nothing is left half-written."""
from pathlib import Path

import numpy as np

from .errors import VctError


def save_png(path, pixels):
    """Write uint8 pixels (H, W, 3) as PNG."""
    from PIL import Image

    write_atomically(path, lambda f: Image.fromarray(pixels, "RGB").save(f, format="PNG"))


def save_npy(path, array):
    """Write linear radiance as float32 .npy."""
    write_atomically(path, lambda f: np.save(f, np.asarray(array, dtype="f4")))


def write_atomically(path, write):
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with open(tmp, "wb") as f:
            write(f)
        tmp.replace(path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise VctError(f"cannot write ({exc.strerror or exc})", source=path) from None
