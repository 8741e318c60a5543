"""The interactive viewer (`vct view`, engine.app.viewer).

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
from engine.app.viewer import inspector
from engine.app.viewer import layout
from engine.app.viewer.camera import FlyCamera
from engine.app.viewer.hot_reload import ShaderWatcher
from engine.app.viewer.playback import Playback
from engine.app.viewer.stats import FrameStats, reused, work_line
from engine.core.errors import VctError

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes" / "cornell_box.json"
ANIMATED = ROOT / "scenes" / "animated_room.glb"  # "Play" (4 s) moves objects, "Dolly" (6 s) the camera
SMALL = (160, 120)
PANELS = ("Overlay", "Scene Graph", "Inspector", "Renderer", "Animation")
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
    from engine.app.viewer.app import Viewer

    return Viewer(scene, engine.RenderSettings(mode=mode, grid=32), size, vsync=False, **kw)


def vct(*args, env=None):
    return subprocess.run([sys.executable, "-m", "engine.app.cli", *map(str, args)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)


def read_png(path):
    return np.asarray(Image.open(path).convert("RGB")).astype(np.int16)


# ---- the window ------------------------------------------------------------------------------

def test_view_frames_screenshot_equals_headless_render(display, tmp_path):
    """A still view, its frames blended by temporal anti-aliasing, shows what `vct render` makes
    with its jittered samples."""
    env = dict(os.environ, DISPLAY=display)
    view_png, render_png = tmp_path / "view.png", tmp_path / "render.png"
    size = ["--mode", "direct", "--grid", "32", "--width", SMALL[0], "--height", SMALL[1]]
    viewed = vct("view", SCENE, "--frames", 20, "--screenshot", view_png, *size, env=env)
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
        image = viewer.layout.image
        np.testing.assert_array_equal(window[image.y:image.y + image.height, image.x:image.x + image.width], frame)
        panels = window[:, :image.x]  # the left column: the overlay and the Scene Graph
        assert panels.std() > 10
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
        with_panels = viewer.window.framebuffer_size
        press(viewer, imgui.Key.f1)  # hidden: the window shrinks to the image, which keeps its size
        run_until(viewer, lambda: viewer.window.framebuffer_size == SMALL, timeout=5.0)
        assert viewer.window.framebuffer_size == SMALL and viewer.renderer.size == SMALL
        assert not viewer.layout.shows_panels
        press(viewer, imgui.Key.f1)
        run_until(viewer, lambda: viewer.window.framebuffer_size == with_panels, timeout=5.0)
        assert viewer.layout.shows_panels and viewer.renderer.size == SMALL
        assert not viewer.window.should_close
        press(viewer, imgui.Key.escape)
        assert viewer.window.should_close
        assert viewer.run() == 0  # the loop ends at once


def imgui_rect(name):
    """Where ImGui drew the window `name` last frame, as a layout.Rect; None if it did not."""
    from imgui_bundle import imgui

    window = imgui.internal.find_window_by_name(name)
    if window is None or not window.active:
        return None
    return layout.Rect(round(window.pos.x), round(window.pos.y), round(window.size.x), round(window.size.y))


@pytest.mark.parametrize("path, size", [(SCENE, SMALL), (SCENE, (256, 256)), (ANIMATED, (200, 700))],
                         ids=["small-image", "camera-size", "tall-animated"])
def test_the_window_opens_with_its_panels_beside_the_image(on_display, path, size):
    """The window is the image plus the panel columns: every panel lies inside the window,
    none overlaps the image or another, and the overlay's text fits in it."""
    from imgui_bundle import imgui

    with open_viewer(engine.load_scene(path), size=size) as viewer:
        viewer.frame()
        viewer.frame()  # auto-sized windows take their size on the first frame, show on the second
        window = layout.Rect(0, 0, *viewer.window.framebuffer_size)
        image = viewer.layout.image
        assert viewer.renderer.size == size == (image.width, image.height)
        assert window.contains(image)
        drawn = {name: imgui_rect(name) for name in PANELS}
        expected = [name for name in PANELS if name != "Animation" or path == ANIMATED]
        assert [name for name in PANELS if drawn[name]] == expected
        for name in expected:
            assert viewer.layout.panels[name].contains(drawn[name]), name
            assert window.contains(drawn[name]) and not drawn[name].overlaps(image), name
            assert not any(drawn[name].overlaps(drawn[other]) for other in expected if other != name), name
        overlay = imgui.internal.find_window_by_name("Overlay")
        assert overlay.scroll_max.x == overlay.scroll_max.y == 0  # nothing of its text is cut off


def test_a_window_too_small_for_the_panels_shows_the_image_alone(on_display, scene):
    with open_viewer(scene) as viewer:
        viewer.frame()
        viewer.window.set_size(400, 300)  # resized by the user: the image takes the whole window
        run_until(viewer, lambda: viewer.renderer.size == (400, 300), timeout=5.0)
        viewer.frame()
        assert viewer.renderer.size == (400, 300) and viewer.layout.panels == {}
        assert all(imgui_rect(name) is None for name in PANELS)
        viewer.window.set_size(1000, 700)  # room for both columns: the image between them
        run_until(viewer, lambda: viewer.renderer.size == (1000 - layout.LEFT_COLUMN - layout.RIGHT_COLUMN, 700),
                  timeout=5.0)
        viewer.frame()
        assert viewer.layout.shows_panels and not imgui_rect("Inspector").overlaps(viewer.layout.image)


def test_an_animated_scene_plays_pauses_and_scrubs(on_display):
    scene = engine.load_scene(ANIMATED)
    with open_viewer(scene) as viewer:
        blue = scene.root.find("Blue")  # "Play" moves it along z
        viewer.frame(dt=0.5)
        start = blue.translation.copy()
        before = viewer.frame_pixels().astype(int)
        viewer.frame(dt=0.5)
        viewer.frame(dt=0.5)
        assert viewer.playback.time == pytest.approx(1.5)
        assert not np.allclose(blue.translation, start)
        assert np.abs(viewer.frame_pixels().astype(int) - before).mean() > 1

        viewer.playback.playing = False  # the Pause button
        viewer.frame(dt=0.5)  # shows the time it had come to, 1.5 s
        paused = blue.translation.copy()
        viewer.frame(dt=0.5)
        viewer.frame(dt=0.5)
        assert viewer.playback.time == pytest.approx(1.5)
        np.testing.assert_array_equal(blue.translation, paused)

        viewer.playback.seek(1.0)  # the time slider
        viewer.frame(dt=0.5)
        at_one_second = engine.load_scene(ANIMATED).pose_at(1.0).root.find("Blue")
        np.testing.assert_allclose(blue.translation, at_one_second.translation)


def test_the_fly_camera_takes_over_from_an_animated_camera_until_reset(on_display):
    from imgui_bundle import imgui

    scene = engine.load_scene(ANIMATED)
    with open_viewer(scene) as viewer:
        viewer.frame(dt=1.0)
        viewer.frame(dt=1.0)
        dolly = scene.camera.position.copy()  # the file's camera at t = 1 s
        np.testing.assert_allclose(dolly, engine.load_scene(ANIMATED).pose_at(1.0).camera.position)
        imgui.get_io().add_key_event(imgui.Key.w, True)
        viewer.frame(dt=0.1)
        imgui.get_io().add_key_event(imgui.Key.w, False)
        viewer.frame(dt=0.1)
        flown = scene.camera.position.copy()
        assert not np.allclose(flown, dolly)
        viewer.frame(dt=1.0)  # the animation plays on, the view stays the user's
        np.testing.assert_allclose(scene.camera.position, flown)
        imgui.get_io().add_key_event(imgui.Key.r, True)
        viewer.frame(dt=1.0)
        imgui.get_io().add_key_event(imgui.Key.r, False)
        viewer.frame(dt=1.0)
        at = viewer.playback.time - 1.0  # the frame rendered before this last advance
        np.testing.assert_allclose(scene.camera.position, engine.load_scene(ANIMATED).pose_at(at).camera.position)


def test_view_frames_plays_the_animations_as_render_poses_them(display, tmp_path):
    """`vct view --frames N`: frame i shows t = i / 30 s, so its screenshot is `vct render
    --time (N-1)/30` (the camera dollies and the objects move, so no other time matches). Both
    see the pixel centres: the last frame alone, not a history of the frames before it."""
    env = dict(os.environ, DISPLAY=display)
    view_png, render_png = tmp_path / "view.png", tmp_path / "render.png"
    size = ["--mode", "direct", "--width", SMALL[0], "--height", SMALL[1]]
    viewed = vct("view", ANIMATED, "--frames", 16, "--screenshot", view_png, "--no-temporal-aa", *size, env=env)
    assert viewed.returncode == 0, viewed.stderr
    assert vct("render", ANIMATED, "--time", 0.5, "--samples", "1", "--out", render_png, *size).returncode == 0
    a, b = read_png(view_png), read_png(render_png)
    assert np.abs(a - b).mean() < 1.0 and a.std() > 10


@pytest.mark.parametrize("mode, camera_frame, static_frame", [
    ("direct", "reused shadow maps", "reused G-buffer, shadow maps, direct light"),
    ("gi", "reused shadow maps, voxels", "reused G-buffer, shadow maps, direct light, voxels"),
])
def test_the_overlay_says_what_a_frame_reused(on_display, scene, mode, camera_frame, static_frame):
    from imgui_bundle import imgui

    from engine.app.viewer.panels import overlay_lines

    def work(viewer):
        lines = [line[0] for line in overlay_lines(viewer.frames, viewer.process, viewer.renderer, False) if line]
        assert not any("Draw calls" in line or line.startswith("0 draw calls") for line in lines), lines
        return lines

    with open_viewer(scene, mode=mode) as viewer:
        viewer.frame()
        viewer.frame()
        assert static_frame in work(viewer)  # nothing changed: the frame drew nothing
        imgui.get_io().add_key_event(imgui.Key.w, True)
        viewer.frame()  # the camera moved: the G-buffer and the direct light again
        imgui.get_io().add_key_event(imgui.Key.w, False)
        draws = viewer.renderer.draw_calls
        assert draws > 0 and f"{draws} draw calls; {camera_frame}" in work(viewer)
        host = next(line for line in work(viewer) if line.startswith("host "))  # the host's ms and the GPU's, apart
        assert float(host.split()[1]) > 0.0 and host.split()[3] == "GPU" and float(host.split()[4]) > 0.0, host
        if mode == "gi":  # the voxels' GPU memory, in all and per voxel of the grid
            grid = viewer.renderer.voxel_layout.n
            per_voxel = viewer.renderer.voxel_memory_bytes() / grid ** 3
            assert any(line.startswith("voxels ") and f"({per_voxel:.0f} B/voxel)" in line for line in work(viewer))


def test_the_viewer_flies_through_a_clipmap_moving_one_level_a_frame(on_display, scene):
    """A scene with a clipmap in the viewer: the overlay names it, and flying forward moves its
    levels one a frame, until every level follows the camera."""
    from imgui_bundle import imgui

    from engine.voxels.clipmap import level_regions, moved_levels
    from engine.scene.model import Clipmap
    from engine.app.viewer.panels import overlay_lines

    scene.clipmap = Clipmap(levels=3, resolution=16, voxel_size=0.05)
    with open_viewer(scene, mode="gi") as viewer:
        viewer.frame()
        lines = [line[0] for line in overlay_lines(viewer.frames, viewer.process, viewer.renderer, False) if line]
        assert any("clipmap 3 x 16^3" in line for line in lines), lines
        start, placements = viewer.renderer.voxel_layout.regions, set()
        imgui.get_io().add_key_event(imgui.Key.w, True)
        for _ in range(20):
            held = viewer.renderer.voxel_layout.regions
            viewer.frame()
            assert len(moved_levels(held, viewer.renderer.voxel_layout.regions)) <= 1  # one level a frame
            placements.add(viewer.renderer.voxel_layout.regions[0].center.tobytes())
        imgui.get_io().add_key_event(imgui.Key.w, False)
        assert len(placements) > 1 and moved_levels(start, viewer.renderer.voxel_layout.regions)
        for _ in range(3):
            viewer.frame()
        assert not moved_levels(viewer.renderer.voxel_layout.regions, level_regions(scene.clipmap, scene.camera.position))


# ---- no display needed -------------------------------------------------------------------------

def test_layout_puts_the_image_between_the_panel_columns():
    window = layout.window_size_for((256, 256), True)
    assert window == (layout.LEFT_COLUMN + 256 + layout.RIGHT_COLUMN, layout.PANELS_MIN_HEIGHT)
    placed = layout.layout(window, (256, 256), True, animated=True)
    assert placed.image == layout.Rect(layout.LEFT_COLUMN, (layout.PANELS_MIN_HEIGHT - 256) // 2, 256, 256)
    rects = list(placed.panels.values())
    assert len(rects) == 5 and all(placed.window.contains(r) and not r.overlaps(placed.image) for r in rects)
    assert not any(a.overlaps(b) for i, a in enumerate(rects) for b in rects[i + 1:])
    assert layout.window_size_for((256, 256), False) == (256, 256)
    assert layout.layout((256, 256), (256, 256), True, animated=False).panels == {}  # no room: the image alone
    assert layout.image_area((1000, 700), True) == layout.Rect(layout.LEFT_COLUMN, 0, 440, 700)


def test_playback_advances_loops_pauses_and_chooses():
    playback = Playback({"Play": 4.0, "Dolly": 6.0})
    assert playback.playing and playback.duration == 6.0
    playback.speed = 2.0
    playback.advance(2.0)
    assert playback.time == pytest.approx(4.0)
    playback.advance(1.5)
    assert playback.time == pytest.approx(1.0)  # 7 s loops over the longest, 6 s
    playback.choose("Play")
    assert playback.duration == 4.0 and playback.time == pytest.approx(1.0)
    playback.playing = False
    playback.advance(1.0)
    assert playback.time == pytest.approx(1.0)
    playback.seek(9.0)
    assert playback.time == 4.0

    posed = []
    scene = type("Scene", (), {"pose_at": lambda self, t, animation: posed.append((t, animation))})()
    assert playback.pose(scene) and not playback.pose(scene)  # posed again only after a change
    playback.seek(2.0)
    assert playback.pose(scene) and posed == [(4.0, "Play"), (2.0, "Play")]
    assert not Playback({}).playing and not Playback({}).pose(scene)


def test_reuse_names_what_a_frame_did_not_run():
    camera_frame = ["gbuffer", "lighting", "cone_trace", "tonemap"]
    assert reused(camera_frame) == ["shadow maps", "voxels"]
    assert work_line(camera_frame, 7) == "7 draw calls; reused shadow maps, voxels"
    assert work_line(["tonemap"], 0) == "reused G-buffer, shadow maps, direct light"  # direct mode, nothing changed
    assert reused(["gbuffer_view"]) == ["G-buffer"]  # a G-buffer view needs no light
    assert work_line(["shadow", "gbuffer", "lighting", "voxelize", "cone_trace"], 12) == "12 draw calls"


def test_fly_camera_follows_an_animated_camera_until_moved(scene):
    camera = FlyCamera(scene.camera)
    animated = engine.load_scene(SCENE).camera  # where an animation puts the scene's camera

    def dolly():
        animated.position = animated.position + [0.2, 0.0, 0.0]
        animated.look_at = animated.look_at + [0.2, 0.0, 0.0]
        camera.follow(animated)

    dolly()
    camera.apply(scene.camera)
    np.testing.assert_allclose(scene.camera.position, animated.position)
    camera.update(0.1, move=(0, 0, 1))
    camera.apply(scene.camera)
    flown = scene.camera.position.copy()
    dolly()  # the animation moves on, the view stays the user's
    camera.apply(scene.camera)
    np.testing.assert_allclose(scene.camera.position, flown)
    camera.reset()  # R: back to the animated view
    camera.apply(scene.camera)
    np.testing.assert_allclose(scene.camera.position, animated.position)



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
    for frame in range(21):
        stats.host(0.1 if frame == 0 else 0.002)  # the host's share of each frame: the first one falls out
        stats.tick()
        now[0] += 0.05
    assert stats.ms_per_frame == pytest.approx(50.0)
    assert stats.fps == pytest.approx(20.0)
    assert stats.host_ms == pytest.approx(2.0)


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
    line = 1 + (glsl / "lighting/shade_lights.frag").read_text().splitlines().index('#include "lib/brdf.glsl"')
    out = io.StringIO()
    with engine.Renderer(16, 16, glsl_root=glsl) as renderer:
        watcher = ShaderWatcher(renderer, stream=out)
        brdf.unlink()
        errors = watcher.poll(force=True)
        assert f'glsl/lighting/shade_lights.frag:{line}: error: #include "lib/brdf.glsl": no such file' in errors
        assert all(e.endswith('error: #include "lib/brdf.glsl": no such file') for e in errors), errors
        assert out.getvalue().count("no such file") == len(errors)
        brdf.write_text(text)
        assert watcher.poll(force=True) == []
        assert "shader errors fixed" in out.getvalue()
