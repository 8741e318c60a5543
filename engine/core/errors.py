"""User-facing errors and warnings: one line that names the file and the field at fault."""
import warnings


def one_line(text):
    """`text` as one line: control characters (a newline or tab in a path, an escape) and line
    separators written as their Python escapes (\\n, \\x1b, \\u2028)."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in str(text))


class VctError(Exception):
    """An error the CLI reports as one line and exit code 2 (bad input, no OpenGL 4.5, ...).
    The message is one line whatever the names in it hold (one_line)."""

    def __init__(self, message, source=None, field=None):
        self.message = message  # without its source and field
        self.source = str(source) if source is not None else None
        self.field = field
        super().__init__(_located(message, self.source, field))


class SceneError(VctError):
    """A scene file that cannot be loaded: malformed JSON, unknown type, bad value."""


class ShaderError(VctError):
    """A GLSL program that failed to compile or link; the message names the real file and line."""


class ContextError(VctError):
    """No OpenGL 4.5 context could be created."""


class VctWarning(UserWarning):
    """Something the user can fix that does not stop the work (triangles dropped from a mesh
    file); the CLI prints it as one line `vct: warning: ...`."""


def warn(message, source=None, field=None):
    """Issue a VctWarning, worded as VctError words an error."""
    warnings.warn(VctWarning(_located(message, source, field)), stacklevel=2)


def _located(message, source, field):
    """`source: field: message`, the parts there are, as one line."""
    where = "".join(f"{part}: " for part in (source, field) if part)
    return one_line(where + message)
