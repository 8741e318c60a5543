"""User-facing errors: one line that names the file and the field at fault."""


class VctError(Exception):
    """An error the CLI reports as one line and exit code 2 (bad input, no OpenGL 4.5, ...)."""

    def __init__(self, message, source=None, field=None):
        self.source = str(source) if source is not None else None
        self.field = field
        where = ""
        if self.source and field:
            where = f"{self.source}: {field}: "
        elif self.source:
            where = f"{self.source}: "
        elif field:
            where = f"{field}: "
        super().__init__(where + message)


class SceneError(VctError):
    """A scene file that cannot be loaded: malformed JSON, unknown type, bad value."""


class ShaderError(VctError):
    """A GLSL program that failed to compile or link; the message names the real file and line."""


class ContextError(VctError):
    """No OpenGL 4.5 context could be created."""
