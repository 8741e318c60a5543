"""`vct view`: the interactive viewer, a thin client of engine.Renderer in a glfw window.

    with Viewer(scene, settings, (640, 480)) as viewer:   # the image's size
        viewer.run()                  # until Esc or the window closes
        # or, for tests: viewer.frame(); viewer.frame_pixels(); viewer.shaders.poll(force=True)

The window opens at the image's size plus the panel columns beside it (engine.app.viewer.layout);
the image keeps its size until the user resizes the window, then takes the room the columns
leave. An animated scene plays (engine.app.viewer.playback), posed before each frame renders.

Keys: WASD/QE move, drag to look, scroll for speed (Shift: faster), R reset camera,
V vsync, F1 panels, F12/PrtScrn screenshot of the frame (Shift+F12: the whole window,
panels included), Esc quit.
"""
import sys
import time

import numpy as np
from imgui_bundle import imgui

from ...core.errors import VctError
from ...formats.output import save_png
from ...frame.renderer import Renderer
from ...gpu.shaders import GLSL_ROOT
from . import panels
from .camera import FlyCamera
from .gui import Gui
from .hot_reload import ShaderWatcher
from .layout import image_area, layout, window_size_for
from .playback import Playback
from .present import Presenter
from .screenshots import screenshot_path
from .stats import FrameStats, ProcessStats
from .window import Window

MOVE_KEYS = {  # key -> (right, up, forward)
    imgui.Key.w: (0, 0, 1), imgui.Key.s: (0, 0, -1),
    imgui.Key.d: (1, 0, 0), imgui.Key.a: (-1, 0, 0),
    imgui.Key.e: (0, 1, 0), imgui.Key.q: (0, -1, 0),
}
FIXED_FRAME_SECONDS = 1 / 30  # what each frame of run(frames) advances the animations by


class Viewer:
    def __init__(self, scene, settings, size, glsl_root=GLSL_ROOT, show_panels=True, vsync=True,
                 visible=True, animation=None):
        import moderngl

        self.scene = scene
        self.settings = settings.validate()
        self.show_panels = show_panels  # wanted; shown where the window has room (layout.panels_fit)
        self.playback = Playback(scene.animations())
        if animation is not None:  # a name of scene.animations() (the CLI checks it)
            self.playback.choose(animation)
        self.selected = next((node.name for node, _ in scene.lights()), None)
        self.settings_message = None
        self._pending_screenshot = None  # "frame" or "window" after F12 / PrtScrn (Shift: window)
        self._window_size = window_size_for(size, show_panels)  # as of the last frame
        self._asked_window_size = None  # the size F1 asked the window for, until it changes
        self.layout = layout(self._window_size, size, show_panels, bool(self.playback.durations))
        self.window = self.gui = self.renderer = self.presenter = None
        try:
            self.window = Window(*self._window_size, self._title(), visible=visible, vsync=vsync)
            self.ctx = moderngl.create_context(require=450)
            self.renderer = Renderer(*size, settings=self.settings, ctx=self.ctx, glsl_root=glsl_root)
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
        hidden = "" if self.layout.shows_panels else ", F1: panels"
        return f"vct view - {self.scene.root.name} ({self.settings.mode}{hidden})"

    # -- one frame ---------------------------------------------------------------------------

    def frame(self, capture_window=False, dt=None):
        """Input, hot reload, render, present, panels, swap. `dt` is the seconds the frame
        stands for (None: the wall-clock time since the last frame): the camera moves by it and,
        after the frame, the animations advance by it times their speed. With `capture_window`,
        returns the whole window (panels included) as uint8 (H, W, 3), read before the swap."""
        self.window.poll_events()
        now = time.perf_counter()
        wall, self._last_frame = now - self._last_frame, now
        dt = wall if dt is None else dt
        self.gui.new_frame()
        self._handle_input(dt)
        self.shaders.poll()
        size = tuple(self.window.framebuffer_size)
        pixels = None
        if size[0] > 0 and size[1] > 0:  # not minimized
            self._follow_window(size)
            self._lay_out(size)
            self._render()
            self.presenter.draw(self.renderer.display_target().texture, self.layout.image, size)
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
        self.playback.advance(dt)
        return pixels

    def _follow_window(self, size):
        """When the window's size changed other than as F1 asked (the user or the window manager
        resized it), the image takes the room the panels leave."""
        if size == self._window_size:
            return
        self._window_size = size
        asked, self._asked_window_size = self._asked_window_size, None
        if size != asked:
            area = image_area(size, self.show_panels)
            self.renderer.resize(area.width, area.height)

    def _lay_out(self, size):
        shown = self.layout.shows_panels
        self.layout = layout(size, self.renderer.size, self.show_panels, bool(self.playback.durations))
        if self.layout.shows_panels != shown:
            self.window.set_title(self._title())

    def _toggle_panels(self):
        """F1: show the panels if hidden, else hide them; the window grows or shrinks by their
        columns, so the image keeps its size."""
        self.show_panels = not self.layout.shows_panels
        self._asked_window_size = window_size_for(self.renderer.size, self.show_panels)
        self.window.set_size(*self._asked_window_size)

    def _render(self):
        if self.playback.pose(self.scene) and self.scene.camera_node is not None:
            self.camera.follow(self.scene.camera)  # pose_at placed the camera on its (animated) node
        self.camera.apply(self.scene.camera)
        start = time.perf_counter()
        try:
            self.renderer.render_frame(self.scene, self.settings)
        except VctError as exc:  # a setting the renderer refuses (e.g. memory): back to the last good
            self.settings_message = str(exc)
            self.settings = self.renderer.settings
            self.renderer.render_frame(self.scene, self.settings)
        self.frames.host(time.perf_counter() - start)

    def _draw_panels(self, size):
        panels.draw_shader_errors(self.shaders.errors, size)
        rects = self.layout.panels
        if not rects:
            return
        panels.draw_overlay(panels.overlay_lines(self.frames, self.process, self.renderer, self.window.vsync),
                            rects["Overlay"])
        self.selected = panels.draw_scene_graph(self.scene, self.selected, rects["Scene Graph"])
        panels.draw_inspector(self.scene, self.selected, rects["Inspector"])
        changed = panels.draw_renderer_panel(self.settings, rects["Renderer"], max(self.renderer.voxel_layout.levels, 1),
                                             self.settings_message)
        if changed is not None:
            self.apply_settings(changed)
        if "Animation" in rects:
            panels.draw_animation_panel(self.playback, rects["Animation"])

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
                self._toggle_panels()
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
        """Run until Esc / the window closes, or for `frames` frames: then each frame advances
        the animations by FIXED_FRAME_SECONDS (frame i shows t = i / 30 s), as `vct render`
        poses them."""
        count = 0
        dt = None if frames is None else FIXED_FRAME_SECONDS
        while not self.window.should_close and (frames is None or count < frames):
            self.frame(dt=dt)
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
