"""Writing results: tone-mapped PNG, linear float32 .npy or OpenEXR, reports.

Files are written all or nothing: each to a new temporary file with a unique name in its
target's directory, and only when every one is complete are they moved over their targets
(os.replace, atomic). A failure before that leaves every file that was there as it was and
removes only this call's own temporary files, so concurrent writers to the same paths never
delete each other's results. (Should a move itself fail after another succeeded, which the
checks before the moves leave to races with other programs, the files moved stay moved.)"""
import contextlib
import errno
import os
import secrets
import stat
from pathlib import Path

import numpy as np

from ..core.errors import VctError


def png_writer(pixels):
    """A writer of uint8 pixels (H, W, 3) as PNG, for write_files."""
    from PIL import Image

    return lambda f: Image.fromarray(pixels, "RGB").save(f, format="PNG")


def npy_writer(array):
    """A writer of an array as float32 .npy, for write_files."""
    return lambda f: np.save(f, np.asarray(array, dtype="f4"))


def save_png(path, pixels):
    """Write uint8 pixels (H, W, 3) as PNG."""
    write_files([(path, png_writer(pixels))])


def save_npy(path, array):
    """Write linear radiance as float32 .npy."""
    write_files([(path, npy_writer(array))])


def save_exr(path, array):
    """Write linear radiance as float32 RGB OpenEXR."""
    write_files([(path, exr_writer(array))])


def exr_writer(array):
    """A writer of linear radiance (H, W, 3), row 0 at the top, as a float32 RGB OpenEXR (ZIP
    compressed): the same values as the .npy, readable by any HDR tool; for write_files."""
    import OpenEXR

    pixels = np.ascontiguousarray(array, dtype="f4")
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    return lambda f: OpenEXR.File(header, {"RGB": pixels}).write(f)


HDR_WRITERS = {".npy": npy_writer, ".exr": exr_writer}


def hdr_writer(path, array):
    """A writer of linear radiance in the format the suffix of `path` names (HDR_WRITERS)."""
    return HDR_WRITERS[Path(path).suffix.lower()](array)


def check_target(path):
    """Raise OSError where a file should not be moved to `path`: a directory or a device such
    as /dev/null is there, or the name is too long for the file system (or a component of the
    path is not a directory)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return
    if stat.S_ISDIR(mode):
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(path))
    if not stat.S_ISREG(mode):
        raise OSError("not a regular file")


def write_files(outputs):
    """Write [(path, write(binary file)), ...] all or nothing (see the module docstring).
    Raises VctError naming the path that failed."""
    temporaries = []  # (temporary path, target path), not yet moved
    target = None
    try:
        for target, write in outputs:
            target = Path(target)
            check_target(target)
            temporary = target.parent / f".vct-{secrets.token_hex(8)}.tmp"
            temporaries.append((temporary, target))  # before it exists: an interrupt from here on removes it
            try:
                descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # mode as open() gives
            except OSError:
                temporaries.pop()  # nothing was created
                raise
            with os.fdopen(descriptor, "wb") as f:
                write(f)
        while temporaries:
            temporary, target = temporaries[0]
            os.replace(temporary, target)
            temporaries.pop(0)
    except OSError as exc:
        raise VctError(f"cannot write ({exc.strerror or exc})", source=target) from None
    finally:  # whatever failed (a writer may raise anything, a signal may interrupt): remove what was not moved
        for temporary, _ in temporaries:
            with contextlib.suppress(OSError):
                temporary.unlink(missing_ok=True)
