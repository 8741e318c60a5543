"""The viewer's window: glfw with an OpenGL 4.5 core context, made current.

imgui_bundle is imported before glfw on purpose: it points pyGLFW at the glfw library it
ships (PYGLFW_LIBRARY), so that ImGui's native glfw backend and this module drive one glfw.
"""
import os

import imgui_bundle  # noqa: F401  (must come before `import glfw`, see above)
import glfw

from ...core.errors import ContextError, VctError

GL_VERSION = (4, 5)


class Window:
    def __init__(self, width, height, title, visible=True, vsync=True):
        self._messages = []
        _check_same_glfw()
        glfw.set_error_callback(lambda code, text: self._messages.append(_text(text)))
        if not glfw.init():
            raise VctError(f"cannot open a window: {self._reason('glfw could not start')}"
                           + ("" if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
                              else " (no display: set DISPLAY, or run under Xvfb)"))
        glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, GL_VERSION[0])
        glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, GL_VERSION[1])
        glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
        glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
        glfw.window_hint(glfw.VISIBLE, bool(visible))
        glfw.window_hint(glfw.RESIZABLE, True)
        self.handle = glfw.create_window(int(width), int(height), title, None, None)
        if not self.handle:
            reason = self._reason("unknown reason")
            glfw.terminate()
            raise ContextError(f"cannot create an OpenGL {GL_VERSION[0]}.{GL_VERSION[1]} core window: {reason}")
        glfw.make_context_current(self.handle)
        self.vsync = None
        self.set_vsync(vsync)

    def _reason(self, default):
        return self._messages[-1] if self._messages else default

    @property
    def framebuffer_size(self):
        return glfw.get_framebuffer_size(self.handle)

    @property
    def should_close(self):
        return glfw.window_should_close(self.handle)

    def request_close(self):
        glfw.set_window_should_close(self.handle, True)

    def set_title(self, title):
        glfw.set_window_title(self.handle, title)

    def set_size(self, width, height):
        glfw.set_window_size(self.handle, int(width), int(height))

    def set_vsync(self, enabled):
        self.vsync = bool(enabled)
        glfw.swap_interval(1 if self.vsync else 0)

    def poll_events(self):
        glfw.poll_events()

    def swap_buffers(self):
        glfw.swap_buffers(self.handle)

    def close(self):
        if self.handle is not None:
            glfw.destroy_window(self.handle)
            self.handle = None
            glfw.terminate()


def _text(text):
    return text.decode(errors="replace") if isinstance(text, bytes) else str(text)


def _check_same_glfw():
    """ImGui's glfw backend must use the library pyGLFW loaded; refuse a mismatch clearly."""
    wanted = os.environ.get("PYGLFW_LIBRARY")
    loaded = getattr(getattr(glfw, "library", None), "glfw", None)
    loaded_name = getattr(loaded, "_name", None)
    if wanted and loaded_name and os.path.realpath(wanted) != os.path.realpath(loaded_name):
        raise VctError(f"glfw was imported before imgui_bundle and loaded {loaded_name}; "
                       "import engine.app.viewer (or imgui_bundle) before glfw")
