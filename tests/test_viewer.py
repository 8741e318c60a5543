"""The interactive viewer (`vct view`, engine.viewer).

The window tests run a real glfw window with an OpenGL 4.5 core context on a private Xvfb
server (started here on a free display number); they skip, saying why, only where no
display can be made. The GL-free parts (camera, inspector edits, stats, hot-reload
bookkeeping) are tested without a display.
"""
import os
import select
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import engine
from engine.errors import VctError
from engine.viewer import inspector
from engine.viewer.camera import FlyCamera
from engine.viewer.hot_reload import ShaderWatcher
from engine.viewer.stats import FrameStats

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes" / "cornell_box.json"
SMALL = (160, 120)
XVFB_START_SECONDS = 15


# ---- display -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def display():
    """A private Xvfb display ":N" (N chosen by Xvfb itself via -displayfd)."""
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip("Xvfb is not installed, so no display can be made for the viewer "
                    "(Debian: apt-get install xvfb; `make test` installs it when run as root)")
    read_fd, write_fd = os.pipe()
    process = subprocess.Popen([xvfb, "-displayfd", str(write_fd), "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
                               pass_fds=(write_fd,), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    os.close(write_fd)
    number = b""
    deadline = time.monotonic() + XVFB_START_SECONDS
    while not number.endswith(b"\n") and time.monotonic() < deadline:
        ready, _, _ = select.select([read_fd], [], [], 0.2)
        if ready:
            chunk = os.read(read_fd, 16)
            if not chunk:
                break
            number += chunk
    os.close(read_fd)
    if not number.strip().isdigit():
        process.kill()
        _, err = process.communicate(timeout=5)
        pytest.skip(f"Xvfb did not start, so no display can be made: {err.decode(errors='replace').strip()[-300:]}")
    try:
        yield f":{number.decode().strip()}"
    finally:
        process.terminate()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@pytest.fixture
def on_display(display, monkeypatch):
    """In-process tests: glfw reads DISPLAY when it starts."""
    monkeypatch.setenv("DISPLAY", display)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    return display


@pytest.fixture
def scene():
    return engine.load_scene(SCENE)


def open_viewer(scene, mode="direct", size=SMALL, **kw):
    from engine.viewer.app import Viewer

    return Viewer(scene, engine.RenderSettings(mode=mode, grid=32), size, vsync=False, **kw)


def vct(*args, env=None):
    return subprocess.run([sys.executable, "-m", "engine.cli", *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)


def read_png(path):
    return np.asarray(Image.open(path).convert("RGB")).astype(np.int16)


# ---- the window ------------------------------------------------------------------------------

def test_view_frames_screenshot_equals_headless_render(display, tmp_path):
    env = dict(os.environ, DISPLAY=display)
    view_png, render_png = tmp_path / "view.png", tmp_path / "render.png"
    size = ["--mode", "direct", "--grid", "32", "--width", SMALL[0], "--height", SMALL[1]]
    viewed = vct("view", SCENE, "--frames", 3, "--screenshot", view_png, *size, env=env)
    assert viewed.returncode == 0, viewed.stderr
    rendered = vct("render", SCENE, "--out", render_png, *size)
    assert rendered.returncode == 0, rendered.stderr
    a, b = read_png(view_png), read_png(render_png)
    assert a.shape == b.shape == (SMALL[1], SMALL[0], 3)
    assert np.abs(a - b).mean() < 1.0
    assert a.std() > 10  # a real image, not a blank window


def test_a_gltf_file_is_viewed_from_its_own_camera_as_it_renders(display, tmp_path):
    """`vct view room.glb`: the file is the scene, seen from its camera, lit by its KHR lights."""
    env = dict(os.environ, DISPLAY=display)
    room = ROOT / "scenes" / "references" / "gltf_room.glb"
    view_png, render_png = tmp_path / "view.png", tmp_path / "render.png"
    size = ["--mode", "direct", "--width", SMALL[0], "--height", SMALL[1]]
    viewed = vct("view", room, "--frames", 3, "--screenshot", view_png, *size, env=env)
    assert viewed.returncode == 0, viewed.stderr
    assert vct("render", room, "--out", render_png, *size).returncode == 0
    a, b = read_png(view_png), read_png(render_png)
    assert np.abs(a - b).mean() < 1.0 and a.std() > 10


def test_view_without_display_is_one_line_error(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    result = vct("view", SCENE, "--frames", 1, env=env)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("vct: error: cannot open a window"), result.stderr


SYNTAX_ERROR = "float s = blinn_phong_exponent(roughness) +;"
UNKNOWN_FUNCTION = "float s = blinn_phong_exponent_typo(roughness);"
BROKEN_SHADERS = [  # (the broken line, the name of the temporary copy of glsl/)
    pytest.param(SYNTAX_ERROR, "glsl", id="syntax-error"),
    pytest.param(UNKNOWN_FUNCTION, "glsl", id="unknown-function"),
    pytest.param(SYNTAX_ERROR, "shaders-copy", id="copy-not-named-glsl"),
]


@pytest.mark.parametrize("broken, directory", BROKEN_SHADERS)
def test_broken_shader_keeps_rendering_and_reports_file_and_line(on_display, scene, tmp_path, capsys, broken, directory):
    glsl = tmp_path / directory
    shutil.copytree(ROOT / "glsl", glsl)
    brdf = glsl / "lib" / "brdf.glsl"
    good = brdf.read_text()
    target = "float s = blinn_phong_exponent(roughness);"
    line = next(i for i, text in enumerate(good.splitlines(), 1) if target in text)
    with open_viewer(scene, glsl_root=glsl) as viewer:
        viewer.frame()
        assert not _has_error_text(viewer.frame(capture_window=True))
        before = viewer.frame_pixels()
        capsys.readouterr()

        brdf.write_text(good.replace(target, broken))
        seconds = run_until(viewer, lambda: viewer.shaders.errors, timeout=5.0)
        assert viewer.shaders.errors, "the broken file was not reported"
        assert seconds < 2.0  # polled every 0.25 s, then the affected programs recompile (~0.2 s here)
        assert all(message.startswith(f"glsl/lib/brdf.glsl:{line}:") for message in viewer.shaders.errors), \
            viewer.shaders.errors
        viewer.frame()
        np.testing.assert_array_equal(viewer.frame_pixels(), before)  # the last good programs still run
        window = viewer.frame(capture_window=True)
        stderr = capsys.readouterr().err
        assert stderr.count(f"glsl/lib/brdf.glsl:{line}:") == len(viewer.shaders.errors)  # printed once
        assert _has_error_text(window), "the error is not shown in the window"

        brdf.write_text(good)
        run_until(viewer, lambda: not viewer.shaders.errors)
        assert viewer.shaders.errors == []
        assert "fixed" in capsys.readouterr().err
        viewer.frame()
        np.testing.assert_array_equal(viewer.frame_pixels(), before)


def run_until(viewer, condition, timeout=10.0):
    start = time.perf_counter()
    while not condition() and time.perf_counter() - start < timeout:
        viewer.frame()
    return time.perf_counter() - start


def _has_error_text(pixels):
    """Pixels in the error text's colour (panels.ERROR_RED), unlike anything in the Cornell box."""
    r, g, b = (pixels[..., i].astype(int) for i in range(3))
    return int(np.count_nonzero((r >= 230) & (g >= 95) & (g <= 135) & (b >= 85) & (b <= 120))) > 50


@pytest.mark.parametrize("mode", ["direct", "indirect"])
def test_moving_the_light_through_the_inspector_changes_the_image(on_display, scene, mode):
    frames = 1 if mode == "direct" else 3  # indirect: voxels rebuilt, bounces fed frame to frame
    with open_viewer(scene, mode=mode) as viewer:
        for _ in range(frames):
            viewer.frame()
        before = viewer.frame_pixels().astype(int)
        inspector.set_light_position(scene, "Omni Light", [-0.7, 0.0, 0.3])  # next to the red wall
        for _ in range(frames):
            viewer.frame()
        after = viewer.frame_pixels().astype(int)
    assert np.abs(after - before).mean() > 3.0
    left = slice(0, SMALL[0] // 3)
    assert after[:, left].mean() > before[:, left].mean()  # the light moved to the left


def test_window_resize_moves_all_targets(on_display, scene):
    with open_viewer(scene) as viewer:
        viewer.frame()
        viewer.window.set_size(200, 150)
        run_until(viewer, lambda: viewer.renderer.size == (200, 150), timeout=5.0)
        assert viewer.renderer.size == (200, 150)
        assert viewer.frame_pixels().shape == (150, 200, 3)
        assert viewer.frame(capture_window=True).shape == (150, 200, 3)


def test_f12_saves_the_frame_without_panels(on_display, scene, tmp_path, monkeypatch, capsys):
    from imgui_bundle import imgui

    monkeypatch.chdir(tmp_path)
    with open_viewer(scene, size=(256, 192)) as viewer:
        viewer.frame()  # ImGui lays auto-sized windows out on their first frame, shows them on the next
        window = viewer.frame(capture_window=True)
        frame = viewer.frame_pixels()
        assert np.abs(window.astype(int) - frame).mean() > 5  # the overlay is drawn over the frame
        imgui.get_io().add_key_event(imgui.Key.f12, True)
        viewer.frame()
        imgui.get_io().add_key_event(imgui.Key.f12, False)
        viewer.frame()
    saved = sorted((tmp_path / "screenshots").glob("cornell_box-*.png"))
    assert len(saved) == 1
    assert f"saved {saved[0].relative_to(tmp_path)}" in capsys.readouterr().out
    np.testing.assert_array_equal(read_png(saved[0]), frame)


def test_keys_drive_the_camera_vsync_panels_and_quit(on_display, scene):
    from imgui_bundle import imgui

    def press(viewer, key, frames=1):
        imgui.get_io().add_key_event(key, True)
        for _ in range(frames):
            viewer.frame()
        imgui.get_io().add_key_event(key, False)
        viewer.frame()

    with open_viewer(scene) as viewer:
        viewer.frame()
        start = scene.camera.position.copy()
        press(viewer, imgui.Key.w, frames=2)
        assert scene.camera.position[2] < start[2]  # forward is -z in the Cornell box
        before = viewer.frame_pixels()
        press(viewer, imgui.Key.r)
        np.testing.assert_array_equal(scene.camera.position, start)
        assert np.abs(viewer.frame_pixels().astype(int) - before).mean() > 1  # the view changed back
        vsync = viewer.window.vsync
        press(viewer, imgui.Key.v)
        assert viewer.window.vsync is not vsync
        assert viewer.show_panels is False  # a window this small starts with the overlay only
        press(viewer, imgui.Key.f1)
        assert viewer.show_panels is True
        assert not viewer.window.should_close
        press(viewer, imgui.Key.escape)
        assert viewer.window.should_close
        assert viewer.run() == 0  # the loop ends at once


# ---- no display needed -------------------------------------------------------------------------

def test_fly_camera_moves_turns_and_resets(scene):
    camera = FlyCamera(scene.camera)
    start = camera.position.copy()
    camera.update(0.1, move=(0, 0, 1))  # W
    assert camera.position[2] < start[2]  # the scene camera looks down -z
    camera.update(0.1, turn=(50, 0))      # drag right: look right (+x)
    assert camera.forward[0] > 0.1
    camera.update(0.1, turn=(0, 10_000))  # pitch stops short of straight down
    assert abs(camera.forward[1]) < 1.0
    speed = camera.speed
    camera.update(0.1, scroll=2)
    assert camera.speed == pytest.approx(speed * 1.25 ** 2)
    camera.apply(scene.camera)
    assert not np.allclose(scene.camera.position, start)
    camera.reset()
    camera.apply(scene.camera)
    np.testing.assert_array_equal(scene.camera.position, start)
    np.testing.assert_array_equal(scene.camera.look_at, [0.0, 0.0, -1.0])


def test_inspector_edits_the_scene_model(scene):
    inspector.set_light_position(scene, "Omni Light", [0.1, 0.2, 0.3])
    (_, light), = scene.lights()
    np.testing.assert_allclose(light.position, [0.1, 0.2, 0.3])

    inspector.set_light_colour(scene, "Omni Light", [1.0, 0.5, 0.0])
    inspector.set_light_power(scene, "Omni Light", 6.0)
    node = scene.root.find("Omni Light")
    np.testing.assert_allclose(node.light.intensity, [6.0, 3.0, 0.0])
    np.testing.assert_allclose(inspector.light_colour(node.light), [1.0, 0.5, 0.0])

    inspector.set_translation(scene, "Short Box", [0.0, -0.7, 0.0])
    inspector.set_scale(scene, "Short Box", [0.5, -1.0, 0.5])
    assert scene.root.find("Short Box").scale[1] == inspector.MIN_SCALE

    white = scene.root.find("Short Box").material
    assert len(inspector.material_users(scene, white)) == 6
    unique = inspector.make_material_unique(scene, "Short Box")
    inspector.set_albedo(scene, "Short Box", [2.0, 0.5, -1.0])
    np.testing.assert_allclose(unique.albedo, [1.0, 0.5, 0.0])
    np.testing.assert_allclose(white.albedo, [0.73, 0.73, 0.73])  # the other white nodes are untouched
    assert unique.name in scene.materials
    inspector.set_emission(scene, "Short Box", [4.0, 0.0, 0.0])
    inspector.set_roughness(scene, "Short Box", 0.25)
    assert unique.roughness == 0.25 and unique.emission[0] == 4.0

    with pytest.raises(VctError, match="no node named"):
        inspector.set_translation(scene, "Nope", [0, 0, 0])
    with pytest.raises(VctError, match="not a light"):
        inspector.set_light_position(scene, "Tall Box", [0, 0, 0])


def test_frame_stats_average_over_the_last_second():
    now = [0.0]
    stats = FrameStats(window=1.0, clock=lambda: now[0])
    for _ in range(21):
        stats.tick()
        now[0] += 0.05
    assert stats.ms_per_frame == pytest.approx(50.0)
    assert stats.fps == pytest.approx(20.0)


class _FakeRenderer:
    """A Renderer stand-in (and its ProgramLibrary's): `broken` is the current error list."""

    def __init__(self):
        self.broken, self.changed = [], 0
        self.programs = self

    def reload_shaders(self):
        rebuilt, self.changed = self.changed, 0
        return rebuilt, list(self.broken)

    def errors(self):
        return list(self.broken)


def test_shader_watcher_reports_each_change_once():
    import io

    renderer, out = _FakeRenderer(), io.StringIO()
    watcher = ShaderWatcher(renderer, stream=out)
    error = engine.ShaderError("glsl/lib/brdf.glsl:21: error: no function with name 'x'")
    renderer.broken, renderer.changed = [error, error], 2  # one file breaks two programs
    assert watcher.poll(force=True) == ["glsl/lib/brdf.glsl:21: error: no function with name 'x'"]
    watcher.poll(force=True)
    assert out.getvalue().count("brdf.glsl:21") == 1
    renderer.broken, renderer.changed = [], 2
    assert watcher.poll(force=True) == []
    assert "fixed, reloaded 2 programs" in out.getvalue()
    assert watcher.poll() == []  # within the interval: no reload


def test_shader_watcher_shows_a_deleted_shader_file_like_a_compile_error_and_clears_it(tmp_path):
    """A file that preprocessing cannot find (here a deleted library) reaches the viewer's
    error list and stderr with the file and line that include it, and clears when it is back."""
    import io

    glsl = tmp_path / "glsl"
    shutil.copytree(ROOT / "glsl", glsl)
    brdf = glsl / "lib" / "brdf.glsl"
    text = brdf.read_text()
    line = 1 + (glsl / "lighting.frag").read_text().splitlines().index('#include "lib/brdf.glsl"')
    out = io.StringIO()
    with engine.Renderer(16, 16, glsl_root=glsl) as renderer:
        watcher = ShaderWatcher(renderer, stream=out)
        brdf.unlink()
        errors = watcher.poll(force=True)
        assert f'glsl/lighting.frag:{line}: error: #include "lib/brdf.glsl": no such file' in errors
        assert all(e.endswith('error: #include "lib/brdf.glsl": no such file') for e in errors), errors
        assert out.getvalue().count("no such file") == len(errors)
        brdf.write_text(text)
        assert watcher.poll(force=True) == []
        assert "shader errors fixed" in out.getvalue()
