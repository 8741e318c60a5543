"""Reading the files a scene names within the limits of engine/core/limits.py: each one only if it
is a regular file (never a device such as /dev/zero, nor blocking on a pipe), up to a size,
and every image decoded only once its header says it fits."""
import contextlib
import io
import os
import stat
import sys
import tempfile
import warnings

import numpy as np

from ..core.limits import MAX_FILE_BYTES, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, MAX_INPUT_BYTES, MAX_INPUT_PIXELS

# The texture formats read (Pillow's names): the ones models use, each decoded by Pillow's own
# code or a library it links, never through an external interpreter (EPS and PDF go through
# Ghostscript where it is installed).
IMAGE_FORMATS = ("PNG", "JPEG", "WEBP", "BMP", "TGA", "TIFF", "GIF")


def read_regular_file(path, limit):
    """The bytes of `path`, which must be a regular file of at most `limit` bytes. Raises
    OSError saying what is wrong (its strerror reads as a sentence's end)."""
    descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(descriptor, "rb") as f:
        info = os.fstat(descriptor)
        if not stat.S_ISREG(info.st_mode):
            raise OSError(0, "not a regular file")
        data = f.read(limit + 1) if info.st_size <= limit else b""
    if info.st_size > limit or len(data) > limit:  # the size said, or read (a file that grew)
        raise OSError(0, f"larger than {_size(limit)}")
    return data


def os_problem(exc):
    """An OSError (or the ValueError of a NUL in a name) as a few words for a message."""
    if isinstance(exc, FileNotFoundError):
        return "file not found"
    return str(getattr(exc, "strerror", None) or exc)


def _size(limit):
    for unit, name in ((2 ** 30, "GiB"), (2 ** 20, "MiB")):
        if limit % unit == 0:
            return f"{limit // unit} {name}"
    return f"{limit} bytes"


class InputFiles:
    """The files one scene reads and the images they hold, within one budget: each file a
    regular file of at most MAX_FILE_BYTES, all of them together at most MAX_INPUT_BYTES;
    each image at most MAX_IMAGE_SIDE on a side and MAX_IMAGE_PIXELS, the distinct images
    together at most MAX_INPUT_PIXELS. `paths` lists every file read, resolved (an output must
    not overwrite one of them)."""

    def __init__(self):
        self.paths = []
        self.bytes = 0
        self.pixels = 0

    def read(self, path, limit=MAX_FILE_BYTES):
        """The bytes of the file at `path`; OSError (or ValueError for a NUL in the name) says
        why not."""
        data = read_regular_file(path, limit)
        if self.bytes + len(data) > MAX_INPUT_BYTES:
            raise OSError(0, f"the scene's files would reach more than {_size(MAX_INPUT_BYTES)} together")
        self.bytes += len(data)
        self.paths.append(os.path.realpath(path))
        return data

    def decode_image(self, data):
        """uint8 (H, W, C), C = 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA), row 0 at the
        top, of an encoded image in one of IMAGE_FORMATS; ValueError says what is wrong."""
        from PIL import Image

        try:
            with warnings.catch_warnings():  # the size limits are ours, not Pillow's bomb warning
                warnings.simplefilter("ignore", Image.DecompressionBombWarning)
                image = Image.open(io.BytesIO(data), formats=IMAGE_FORMATS)
                width, height = image.size
                if max(width, height) > MAX_IMAGE_SIDE:
                    raise ValueError(f"{width}x{height} pixels, more than {MAX_IMAGE_SIDE} on a side")
                if width * height > MAX_IMAGE_PIXELS:
                    raise ValueError(f"{width}x{height} pixels, more than {MAX_IMAGE_PIXELS} in all")
                if self.pixels + width * height > MAX_INPUT_PIXELS:
                    raise ValueError(f"{width}x{height} pixels: the scene's images would hold more than "
                                     f"{MAX_INPUT_PIXELS} pixels together")
                image.load()
        except ValueError:
            raise
        except Image.UnidentifiedImageError:
            raise ValueError(f"cannot decode image (not one of the formats vct reads: {', '.join(IMAGE_FORMATS)})") from None
        except Exception as exc:  # Pillow raises many kinds on broken or unknown data
            raise ValueError(f"cannot decode image ({' '.join(str(exc).split()) or type(exc).__name__})") from None
        self.pixels += width * height
        if image.mode in ("I", "I;16", "I;16B", "I;16L"):  # 16-bit grey: keep the high byte
            pixels = (np.asarray(image).astype(np.uint32) >> 8).astype(np.uint8)
        else:
            if image.mode not in ("L", "LA", "RGB", "RGBA"):
                image = image.convert("RGBA" if "A" in image.mode or "transparency" in image.info else "RGB")
            pixels = np.asarray(image, dtype=np.uint8)
        return np.ascontiguousarray(pixels.reshape(pixels.shape[0], pixels.shape[1], -1))


RADIANCE_MAP_FORMATS = (".exr", ".hdr")


def read_radiance_map(path, inputs):
    """Linear radiance (H, W, 3) float32, row 0 at the top, of an OpenEXR (half or float RGB) or
    Radiance RGBE (.hdr) image read through `inputs`: its size read from its header and held to
    the image limits before its pixels are decoded, every texel finite and non-negative.
    OSError or ValueError says what is wrong."""
    suffix = os.path.splitext(str(path))[1].lower()
    if suffix not in RADIANCE_MAP_FORMATS:
        raise ValueError(f"an environment map is linear radiance: {' or '.join(RADIANCE_MAP_FORMATS)}, not {suffix or 'no suffix'}")
    data = inputs.read(path)
    pixels = _read_exr(data) if suffix == ".exr" else _read_rgbe(data)
    if inputs.pixels + pixels.shape[0] * pixels.shape[1] > MAX_INPUT_PIXELS:
        raise ValueError(f"the scene's images would hold more than {MAX_INPUT_PIXELS} pixels together")
    bad = ~np.isfinite(pixels) | (pixels < 0)
    if bad.any():
        row, column, _ = np.argwhere(bad)[0]
        raise ValueError(f"texel (row {row}, column {column}) is {pixels[row, column].tolist()}: radiance must be finite "
                         "and not negative")
    inputs.pixels += pixels.shape[0] * pixels.shape[1]
    return np.ascontiguousarray(pixels, np.float32)


def _check_map_size(width, height):
    if min(width, height) < 1 or max(width, height) > MAX_IMAGE_SIDE or width * height > MAX_IMAGE_PIXELS:
        raise _MapError(f"{width}x{height} pixels: at most {MAX_IMAGE_SIDE} on a side and {MAX_IMAGE_PIXELS} in all")


class _MapError(ValueError):
    """What vct finds wrong with a radiance map (as against a decoder's own error)."""


@contextlib.contextmanager
def _decoder_output(messages):
    """Standard error and output (fds 2 and 1, and Python's sys.stdout) into temporary files
    while a C library decodes, its lines appended to `messages` (standard error's first): what
    it prints goes into vct's one line, not before it."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = {fd: os.dup(fd) for fd in (2, 1)}
    python_stdout = io.StringIO()
    with tempfile.TemporaryFile() as errors, tempfile.TemporaryFile() as output:
        for fd, captured in ((2, errors), (1, output)):
            os.dup2(captured.fileno(), fd)
        try:
            with contextlib.redirect_stdout(python_stdout):
                yield
        finally:
            for fd, copy in saved.items():
                os.dup2(copy, fd)
                os.close(copy)
            texts = []
            for captured in (errors, output):
                captured.seek(0)
                texts.append(captured.read(4096).decode("utf-8", "replace"))
            texts.append(python_stdout.getvalue())
            messages.extend(line.strip() for text in texts for line in text.splitlines() if line.strip())


def _read_exr(data):
    import OpenEXR

    messages = []
    try:
        with _decoder_output(messages):
            header = OpenEXR.File(io.BytesIO(data), header_only=True).header()
            (x0, y0), (x1, y1) = header["dataWindow"]
            _check_map_size(int(x1) - int(x0) + 1, int(y1) - int(y0) + 1)
            channels = OpenEXR.File(io.BytesIO(data), separate_channels=True).channels()
    except _MapError:
        raise
    except Exception as exc:  # OpenEXR raises RuntimeError, ValueError and others on broken files
        said = messages[0] if messages else " ".join(str(exc).split()) or type(exc).__name__
        raise ValueError(f"cannot decode OpenEXR ({said})") from None
    if messages:  # the library read past a fault it printed
        raise ValueError(f"cannot decode OpenEXR ({messages[0]})")
    missing = [name for name in "RGB" if name not in channels]
    if missing:
        raise ValueError(f"needs channels R, G and B (it has {', '.join(sorted(channels)) or 'none'})")
    planes = [channels[name].pixels for name in "RGB"]
    if any(plane.dtype.kind != "f" for plane in planes):
        raise ValueError("its channels must be floating point (half or float), not integers")
    return np.stack(planes, axis=-1).astype(np.float32)


def _read_rgbe(data):
    """Radiance RGBE: its size line, the line after the header's blank line, read as the
    decoder reads it (words apart by any white space) and checked before decoding; the decoded
    size must be that one."""
    import imagecodecs

    end = data.find(b"\n\n", 0, 65536)
    if not data.startswith(b"#?") or end < 0:
        raise ValueError("not a Radiance RGBE (.hdr) file")
    words = data[end + 2:data.find(b"\n", end + 2, end + 2 + 256)].split()
    if len(words) != 4 or not all(word.isdigit() for word in words[1::2]) or words[0] not in (b"-Y", b"+Y", b"-X", b"+X"):
        raise ValueError("its size line (after the header) must read -Y HEIGHT +X WIDTH")
    if (words[0], words[2]) != (b"-Y", b"+X"):
        raise ValueError(f"orientation {words[0].decode()} {words[2].decode()}: only -Y H +X W (row 0 at the top) is read")
    height, width = int(words[1]), int(words[3])
    _check_map_size(width, height)
    try:
        pixels = imagecodecs.rgbe_decode(data)[..., :3]
    except Exception as exc:  # imagecodecs raises RgbeError and others on broken data
        raise ValueError(f"cannot decode Radiance RGBE ({' '.join(str(exc).split()) or type(exc).__name__})") from None
    if pixels.shape[:2] != (height, width):
        raise ValueError(f"decodes to {pixels.shape[1]}x{pixels.shape[0]} pixels, its size line says {width}x{height}")
    return pixels
