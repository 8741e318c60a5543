"""Dear ImGui (imgui-bundle) on the viewer's window: its native glfw platform backend and
OpenGL 3 renderer backend (C++, shipped in imgui-bundle; no PyOpenGL needed). The renderer
backend saves and restores the GL state it touches, so it can draw over moderngl's frame."""
import ctypes

from imgui_bundle import imgui

GLSL_VERSION = "#version 450"


class Gui:
    def __init__(self, window):
        self.context = imgui.create_context()
        io = imgui.get_io()
        io.set_ini_filename(None)  # no imgui.ini in the working directory
        imgui.style_colors_dark()
        style = imgui.get_style()
        style.window_rounding = 4.0
        style.frame_rounding = 2.0
        style.item_spacing = imgui.ImVec2(style.item_spacing.x, 3.0)  # a little denser: panels over a small window
        style.frame_padding = imgui.ImVec2(style.frame_padding.x, 2.0)
        address = ctypes.cast(window.handle, ctypes.c_void_p).value
        imgui.backends.glfw_init_for_opengl(address, True)
        imgui.backends.opengl3_init(GLSL_VERSION)
        self._open = True

    @property
    def io(self):
        return imgui.get_io()

    def new_frame(self):
        imgui.backends.opengl3_new_frame()
        imgui.backends.glfw_new_frame()
        imgui.new_frame()

    def render(self):
        imgui.render()
        imgui.backends.opengl3_render_draw_data(imgui.get_draw_data())

    def close(self):
        """Shut the backends down (the GL context must still be current)."""
        if self._open:
            imgui.backends.opengl3_shutdown()
            imgui.backends.glfw_shutdown()
            imgui.destroy_context(self.context)
            self._open = False
