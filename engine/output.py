"""Writing results: tone-mapped PNG and linear float32 .npy or OpenEXR, each written atomically
(to a temporary name in the target directory, then moved), so nothing is left half-written."""
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


def save_exr(path, array):
    """Write linear radiance (H, W, 3), row 0 at the top, as a float32 RGB OpenEXR (ZIP
    compressed): the same values as the .npy, readable by any HDR tool."""
    import OpenEXR

    pixels = np.ascontiguousarray(array, dtype="f4")
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    write_atomically(path, lambda f: OpenEXR.File(header, {"RGB": pixels}).write(f))


HDR_WRITERS = {".npy": save_npy, ".exr": save_exr}


def save_hdr(path, array):
    """Write linear radiance in the format the suffix names (see HDR_WRITERS)."""
    HDR_WRITERS[Path(path).suffix.lower()](path, array)


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
