"""`vct view`: the interactive viewer, a thin client of engine.Renderer in a glfw window.

    with Viewer(scene, settings, (640, 480)) as viewer:
        viewer.run()                  # until Esc or the window closes
        # or, for tests: viewer.frame(); viewer.frame_pixels(); viewer.shaders.poll(force=True)

Keys: WASD/QE move, drag to look, scroll for speed (Shift: faster), R reset camera,
V vsync, F1 panels, F12/PrtScrn screenshot of the frame (Shift+F12: the whole window,
panels included), Esc quit.
"""
import sys
import time

import numpy as np
from imgui_bundle import imgui

from ..errors import VctError
from ..output import save_png
from ..renderer import Renderer
from ..shaders import GLSL_ROOT
from . import panels
from .camera import FlyCamera
from .gui import Gui
from .hot_reload import ShaderWatcher
from .panels import PANELS_MIN_WINDOW
from .present import Presenter
from .screenshots import screenshot_path
from .stats import FrameStats, ProcessStats
from .window import Window

MOVE_KEYS = {  # key -> (right, up, forward)
    imgui.Key.w: (0, 0, 1), imgui.Key.s: (0, 0, -1),
    imgui.Key.d: (1, 0, 0), imgui.Key.a: (-1, 0, 0),
    imgui.Key.e: (0, 1, 0), imgui.Key.q: (0, -1, 0),
}


class Viewer:
    def __init__(self, scene, settings, size, glsl_root=GLSL_ROOT, show_panels=True, vsync=True,
                 visible=True):
        import moderngl

        self.scene = scene
        self.settings = settings.validate()
        self.show_panels = show_panels and size[0] >= PANELS_MIN_WINDOW[0] and size[1] >= PANELS_MIN_WINDOW[1]
        self.selected = next((node.name for node, _ in scene.lights()), None)
        self.settings_message = None
        self._pending_screenshot = None  # "frame" or "window" after F12 / PrtScrn (Shift: window)
        self.window = self.gui = self.renderer = self.presenter = None
        try:
            self.window = Window(size[0], size[1], self._title(), visible=visible, vsync=vsync)
            self.ctx = moderngl.create_context(require=450)
            self.renderer = Renderer(*self.window.framebuffer_size, settings=self.settings, ctx=self.ctx,
                                     glsl_root=glsl_root)
            self.renderer.progressive = True  # bounces=0 converges over frames
            self.renderer.measure = True   # per-pass ms for the overlay
            self.presenter = Presenter(self.ctx)
            self.gui = Gui(self.window)
        except Exception:
            self.close()
            raise
        lo, hi = scene.bounds()
        self.camera = FlyCamera(scene.camera, scene_size=float(np.max(hi - lo)) if np.all(hi > lo) else 2.0)
        self.shaders = ShaderWatcher(self.renderer)
        self.frames = FrameStats()
        self.process = ProcessStats()
        self._last_frame = time.perf_counter()

    def _title(self):
        return f"vct view - {self.scene.root.name} ({self.settings.mode})"

    # -- one frame ---------------------------------------------------------------------------

    def frame(self, capture_window=False):
        """Input, hot reload, render, present, panels, swap. With `capture_window`, returns the
        whole window (panels included) as uint8 (H, W, 3), read before the swap."""
        self.window.poll_events()
        now = time.perf_counter()
        dt, self._last_frame = now - self._last_frame, now
        self.gui.new_frame()
        self._handle_input(dt)
        self.shaders.poll()
        size = self.window.framebuffer_size
        pixels = None
        if size[0] > 0 and size[1] > 0:  # not minimized
            if tuple(size) != self.renderer.size:
                self.renderer.resize(*size)
            self._render()
            self.presenter.draw(self.renderer.display_target().texture, size)
            self._draw_panels(size)
            self.gui.render()
            if capture_window or self._pending_screenshot == "window":
                pixels = self.presenter.read_window(size)
            if self._pending_screenshot:
                self._save_pending_screenshot(pixels)
        else:
            imgui.render()
            time.sleep(0.05)
        self.window.swap_buffers()
        self.frames.tick()
        self.process.update()
        return pixels

    def _render(self):
        self.camera.apply(self.scene.camera)
        try:
            self.renderer.render_frame(self.scene, self.settings)
        except VctError as exc:  # a setting the renderer refuses (e.g. memory): back to the last good
            self.settings_message = str(exc)
            self.settings = self.renderer.settings
            self.renderer.render_frame(self.scene, self.settings)

    def _draw_panels(self, size):
        panels.draw_overlay(self.frames, self.process, self.renderer, self.window.vsync, self.show_panels)
        panels.draw_shader_errors(self.shaders.errors, size)
        if not self.show_panels:
            return
        self.selected = panels.draw_scene_graph(self.scene, self.selected, size)
        panels.draw_inspector(self.scene, self.selected, size)
        changed = panels.draw_renderer_panel(self.settings, size, self.settings_message)
        if changed is not None:
            self.apply_settings(changed)

    def apply_settings(self, settings):
        """Use new settings from the next frame on; a refused value is reported in the panel."""
        try:
            self.settings = settings.validate()
            self.settings_message = None
        except VctError as exc:
            self.settings_message = str(exc)
        self.window.set_title(self._title())

    # -- input -------------------------------------------------------------------------------

    def _handle_input(self, dt):
        io = imgui.get_io()
        keys = not io.want_capture_keyboard
        mouse = not io.want_capture_mouse
        if keys:
            if imgui.is_key_pressed(imgui.Key.escape, False):
                self.window.request_close()
            if imgui.is_key_pressed(imgui.Key.r, False):
                self.camera.reset()
            if imgui.is_key_pressed(imgui.Key.v, False):
                self.window.set_vsync(not self.window.vsync)
            if imgui.is_key_pressed(imgui.Key.f1, False):
                self.show_panels = not self.show_panels
        if imgui.is_key_pressed(imgui.Key.f12, False) or imgui.is_key_pressed(imgui.Key.print_screen, False):
            self._pending_screenshot = "window" if io.key_shift else "frame"
        move = np.zeros(3)
        if keys:
            for key, direction in MOVE_KEYS.items():
                if imgui.is_key_down(key):
                    move += direction
        turn = (0.0, 0.0)
        if mouse and (imgui.is_mouse_down(imgui.MouseButton_.left) or imgui.is_mouse_down(imgui.MouseButton_.right)):
            turn = (io.mouse_delta.x, io.mouse_delta.y)
        scroll = io.mouse_wheel if mouse else 0.0
        self.camera.update(dt, move, turn, scroll, fast=io.key_shift)

    # -- screenshots -------------------------------------------------------------------------

    def frame_pixels(self):
        """The last frame, tone-mapped, without panels: uint8 (H, W, 3), row 0 at the top."""
        return self.renderer.tonemapped()

    def save_screenshot(self, path=None):
        """Save the last frame (no panels) as PNG; returns the path."""
        path = path or screenshot_path(self.scene.name)
        save_png(path, self.frame_pixels())
        return path

    def _save_pending_screenshot(self, window_pixels):
        kind, self._pending_screenshot = self._pending_screenshot, None
        try:
            if kind == "frame":
                path = self.save_screenshot()
            else:
                path = screenshot_path(self.scene.name, "-window")
                save_png(path, window_pixels)
        except (VctError, OSError) as exc:  # e.g. a read-only working directory: keep viewing
            print(f"vct view: screenshot not saved: {exc}", file=sys.stderr)
            return
        print(f"saved {path}", flush=True)

    # -- loop --------------------------------------------------------------------------------

    def run(self, frames=None):
        """Run until Esc / the window closes, or for `frames` frames."""
        count = 0
        while not self.window.should_close and (frames is None or count < frames):
            self.frame()
            count += 1
        return count

    def close(self):
        if self.gui is not None:
            self.gui.close()
            self.gui = None
        if self.presenter is not None:
            self.presenter.release()
            self.presenter = None
        if self.renderer is not None:
            self.renderer.close()
            self.renderer = None
        if self.window is not None:
            self.window.close()
            self.window = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
