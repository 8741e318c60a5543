"""The ImGui windows: overlay, Scene Graph, Inspector, Renderer, Animation, shader errors.

Widgets only: every scene edit goes through engine.app.viewer.inspector, every settings change
returns a new RenderSettings that the viewer validates before using it. Each panel fills its
rectangle of the layout (engine.app.viewer.layout), fixed there; what does not fit scrolls.
"""
from imgui_bundle import imgui

from ...core.constants import GRID_SIZES, MAX_INTERLEAVE, MAX_VOXEL_LEVELS
from ...frame.settings import DIFFUSE_CONE_SETS, MODES, TONEMAPS
from . import inspector
from .layout import MARGIN
from .playback import SPEED_RANGE
from .stats import work_line

LABEL_WIDTH = 112  # what a panel's widgets leave for their labels
ERROR_RED = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)
DIM = imgui.ImVec4(0.7, 0.7, 0.7, 1.0)
DOCKED = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize | imgui.WindowFlags_.no_collapse


def _dock(rect):
    """The next window fills `rect`."""
    imgui.set_next_window_pos(imgui.ImVec2(rect.x, rect.y), imgui.Cond_.always)
    imgui.set_next_window_size(imgui.ImVec2(rect.width, rect.height), imgui.Cond_.always)


# ---- overlay --------------------------------------------------------------------------------

def overlay_lines(frames, process, renderer, vsync):
    """The overlay's text as (line, dimmed) pairs, None for the rule above the passes: FPS,
    ms per frame, the host's ms a frame (issuing the frame's work; on llvmpipe, which runs it as
    it is issued, the work too) and the GPU's (its passes', from timer queries a few frames
    back), CPU %, RAM, voxel and texture memory, the image, the ms of each pass the last frame
    measured ran (a frame runs only the passes whose inputs changed), its draw calls and what
    it reused, and the bounces' state."""
    s = renderer.frame_settings
    cpu = "--" if process.cpu_percent is None else f"{process.cpu_percent:.0f}"
    gpu = sum(renderer.timings.values())
    lines = [(f"FPS {frames.fps:6.1f}  SPF {frames.ms_per_frame:7.1f} ms", False),
             (f"host {frames.host_ms:6.2f} ms  GPU {gpu:6.2f} ms", False),
             (f"CPU {cpu:>5} %  RAM {process.ram_mb:7.0f} MB", False),
             (f"{voxel_memory_line(renderer)}  textures {renderer.texture_memory_bytes() / 2 ** 20:.0f} MB", False),
             (f"{renderer.size[0]}x{renderer.size[1]} {s.mode} {grid_line(renderer)}{' vsync' if vsync else ''}", True)]
    if renderer.timings:
        lines.append(None)
        lines += [(f"{name:<16}{ms:8.1f} ms", False) for name, ms in renderer.timings.items()]
        lines.append((f"{'all passes':<16}{sum(renderer.timings.values()):8.1f} ms", True))
    lines.append((work_line(renderer.passes_ran, renderer.draw_calls), True))
    if s.shown.uses_radiance and s.bounces == 0:
        state = "settled" if renderer.idle else "refining" if renderer.refining else "converging"
        lines.append((f"bounces {state} ({renderer.bounce_iterations} so far)", True))
    return lines


def grid_line(renderer):
    """The voxel grid the last frame used: `grid N`, or `clipmap L x N^3` for a clipmap."""
    grid = renderer.voxel_layout
    if grid.levels > 1:
        return f"clipmap {grid.levels} x {grid.n}^3"
    return f"grid {grid.n or renderer.frame_settings.grid}"


def voxel_memory_line(renderer):
    """The voxel grid's GPU memory, in all and per voxel of the grid."""
    if not renderer.voxel_layout.n:
        return "voxels -"
    total = renderer.voxel_memory_bytes()
    return f"voxels {total / 2 ** 20:.0f} MB ({total / renderer.voxel_layout.voxel_count:.0f} B/voxel)"


def draw_overlay(lines, rect):
    """`lines` (overlay_lines) at the top of `rect`, as tall as they need up to its height."""
    imgui.set_next_window_pos(imgui.ImVec2(rect.x, rect.y), imgui.Cond_.always)
    imgui.set_next_window_size_constraints(imgui.ImVec2(rect.width, 0), imgui.ImVec2(rect.width, rect.height))
    flags = (imgui.WindowFlags_.no_decoration | imgui.WindowFlags_.always_auto_resize
             | imgui.WindowFlags_.no_focus_on_appearing | imgui.WindowFlags_.no_nav | imgui.WindowFlags_.no_inputs)
    if imgui.begin("Overlay", None, flags)[0]:
        imgui.push_text_wrap_pos(0.0)  # wrap at the window's edge
        for line in lines:
            if line is None:
                imgui.separator()
            elif line[1]:
                imgui.text_colored(DIM, line[0])
            else:
                imgui.text(line[0])
        imgui.pop_text_wrap_pos()
    imgui.end()


# ---- scene graph ----------------------------------------------------------------------------

def draw_scene_graph(scene, selected, rect):
    """The node tree; returns the name of the selected node."""
    _dock(rect)
    if imgui.begin("Scene Graph", None, DOCKED)[0]:
        selected = _tree(scene.root, selected, depth=0)
    imgui.end()
    return selected


def _tree(node, selected, depth):
    flags = imgui.TreeNodeFlags_.open_on_arrow | imgui.TreeNodeFlags_.span_avail_width
    if not node.children:
        flags |= imgui.TreeNodeFlags_.leaf | imgui.TreeNodeFlags_.no_tree_push_on_open
    if node.name == selected:
        flags |= imgui.TreeNodeFlags_.selected
    if depth == 0:
        flags |= imgui.TreeNodeFlags_.default_open
    opened = imgui.tree_node_ex(f"{node.name}##{id(node)}", flags)
    if imgui.is_item_clicked() and not imgui.is_item_toggled_open():
        selected = node.name
    if opened and node.children:
        for child in node.children:
            selected = _tree(child, selected, depth + 1)
        imgui.tree_pop()
    return selected


# ---- inspector ------------------------------------------------------------------------------

def draw_inspector(scene, selected, rect):
    _dock(rect)
    if imgui.begin("Inspector", None, DOCKED)[0]:
        node = scene.root.find(selected) if selected else None
        if node is None:
            imgui.text_colored(DIM, "Select a node in the Scene Graph.")
        else:
            imgui.push_item_width(rect.width - LABEL_WIDTH)
            imgui.text(node.name)
            _transform(scene, node)
            if node.material is not None:
                _material(scene, node)
            if node.light is not None:
                _light(scene, node)
            imgui.pop_item_width()
    imgui.end()


def _section(label, default_open=True):
    return imgui.collapsing_header(label, imgui.TreeNodeFlags_.default_open if default_open else 0)


def _transform(scene, node):
    if not _section("Transform", default_open=node.light is None):  # a light's interest is its light
        return
    changed, value = imgui.drag_float3("Translation", list(node.translation), 0.01)
    if changed:
        inspector.set_translation(scene, node.name, value)
    changed, value = imgui.drag_float3("Rotation", list(node.rotation_deg), 0.5, format="%.1f")
    if changed:
        inspector.set_rotation(scene, node.name, value)
    changed, value = imgui.drag_float3("Scale", list(node.scale), 0.01, inspector.MIN_SCALE, 100.0)
    if changed:
        inspector.set_scale(scene, node.name, value)


def _material(scene, node):
    material = node.material
    users = inspector.material_users(scene, material)
    if not _section(f"Material: {material.name}###material"):
        return
    if len(users) > 1:
        imgui.text_colored(DIM, f"shared by {len(users)} nodes")
        imgui.same_line()
        if imgui.small_button("Make unique"):
            inspector.make_material_unique(scene, node.name)
    changed, value = imgui.color_edit3("Albedo", list(material.albedo), imgui.ColorEditFlags_.float)
    if changed:
        inspector.set_albedo(scene, node.name, value)
    changed, value = imgui.slider_float("Roughness", float(material.roughness), 0.0, 1.0)
    if changed:
        inspector.set_roughness(scene, node.name, value)
    changed, value = imgui.slider_float("Metalness", float(material.metalness), 0.0, 1.0)
    if changed:
        inspector.set_metalness(scene, node.name, value)
    changed, value = imgui.color_edit3("Emission", list(material.emission),
                                       imgui.ColorEditFlags_.float | imgui.ColorEditFlags_.hdr)
    if changed:
        inspector.set_emission(scene, node.name, value)


def _light(scene, node):
    light = node.light
    if not _section(f"Light: {light.type}###light"):
        return
    changed, value = imgui.color_edit3("Colour", list(inspector.light_colour(light)), imgui.ColorEditFlags_.float)
    if changed:
        inspector.set_light_colour(scene, node.name, value)
    unit = "W/m2" if light.type == "directional" else "W/sr"
    changed, value = imgui.drag_float("Intensity", inspector.light_power(light), 0.02, 0.0, 1e6, f"%.2f {unit}")
    if changed:
        inspector.set_light_power(scene, node.name, value)
    if light.type in ("point", "spot"):
        changed, value = imgui.drag_float3("Position", list(light.position), 0.01)
        if changed:
            inspector.set_light_position(scene, node.name, value)
    if light.type in ("spot", "directional"):
        changed, value = imgui.drag_float3("Direction", list(light.direction), 0.01)
        if changed and any(value):
            inspector.set_light_direction(scene, node.name, value)
    changed, value = imgui.checkbox("Cast shadows", bool(light.cast_shadows))
    if changed:
        inspector.set_light_cast_shadows(scene, node.name, value)


# ---- renderer -------------------------------------------------------------------------------

def draw_renderer_panel(settings, rect, levels, message=None):
    """Render settings (`levels`: how many voxel levels the last frame's grid held); returns the
    changed RenderSettings (not yet validated) or None."""
    _dock(rect)
    changes = {}
    if imgui.begin("Renderer", None, DOCKED)[0]:
        imgui.push_item_width(rect.width - LABEL_WIDTH)
        _combo("Mode", settings.mode, MODES, changes, "mode")
        if settings.shown.stage == "voxel_view":
            changed, mip = imgui.slider_int("Mip level", settings.voxel_mip, 0, settings.grid.bit_length() - 1)
            if changed:
                changes["voxel_mip"] = mip
            if levels > 1:
                changed, level = imgui.slider_int("Voxel level", min(settings.voxel_level, levels - 1), 0, levels - 1)
                if changed:
                    changes["voxel_level"] = level
        grid = _combo("Grid", settings.grid, GRID_SIZES, changes, "grid")
        if grid is not None:
            changes["voxel_mip"] = min(settings.voxel_mip, grid.bit_length() - 1)
        shown_levels = levels if settings.clipmap_levels is None and levels > 1 else settings.clipmap_levels or 0
        changed, clipmap = imgui.slider_int("Clipmap levels", shown_levels, 0, MAX_VOXEL_LEVELS,
                                            "one grid" if shown_levels == 0 else "%d")
        if changed:
            changes["clipmap_levels"] = clipmap
            changes["voxel_level"] = min(settings.voxel_level, max(clipmap - 1, 0))
        changed, bounces = imgui.slider_int("Bounces", settings.bounces, 0, 8,
                                            "converge" if settings.bounces == 0 else "%d")
        if changed:
            changes["bounces"] = bounces
        if settings.bounces == 0:
            changed, interleave = imgui.slider_int("Re-gather 1 in", settings.bounce_interleave, 1, MAX_INTERLEAVE)
            if changed:
                changes["bounce_interleave"] = interleave
        _slider("Cone step", settings.cone_step, 0.05, 2.0, changes, "cone_step")
        _slider("Cone offset", settings.cone_offset, 0.0, 4.0, changes, "cone_offset")
        _combo("Diffuse cones", settings.diffuse_cones, DIFFUSE_CONE_SETS, changes, "diffuse_cones")
        if settings.mode == "ao":
            _slider("AO distance", settings.ao_distance, 0.05, 4.0, changes, "ao_distance")
        _slider("Exposure", settings.exposure, 0.05, 16.0, changes, "exposure", imgui.SliderFlags_.logarithmic)
        _combo("Tone map", settings.tonemap, TONEMAPS, changes, "tonemap")
        changed, temporal_aa = imgui.checkbox("Temporal anti-aliasing", settings.temporal_aa)
        if changed:
            changes["temporal_aa"] = temporal_aa
        if settings.mode == "gi":
            for i, (label, key) in enumerate((("Direct", "direct"), ("Diffuse", "indirect_diffuse"),
                                              ("Specular", "indirect_specular"))):
                if i:
                    imgui.same_line()
                changed, value = imgui.checkbox(label, getattr(settings, key))
                if changed:
                    changes[key] = value
        imgui.pop_item_width()
        if message:
            imgui.push_text_wrap_pos(0.0)
            imgui.text_colored(ERROR_RED, message)
            imgui.pop_text_wrap_pos()
    imgui.end()
    return settings.replace(**changes) if changes else None


def _combo(label, current, options, changes, key):
    chosen = None
    if imgui.begin_combo(label, str(current)):
        for option in options:
            clicked, _ = imgui.selectable(str(option), option == current)
            if clicked and option != current:
                chosen = changes[key] = option
        imgui.end_combo()
    return chosen


def _slider(label, value, low, high, changes, key, flags=0):
    changed, value = imgui.slider_float(label, float(value), low, high, "%.2f", flags)
    if changed:
        changes[key] = value


# ---- animation ------------------------------------------------------------------------------

def draw_animation_panel(playback, rect):
    """Which animation plays, play/pause, speed and a time slider that scrubs; edits `playback`."""
    _dock(rect)
    if imgui.begin("Animation", None, DOCKED)[0]:
        imgui.push_item_width(rect.width - LABEL_WIDTH)
        if imgui.begin_combo("Plays", _animation_label(playback, playback.animation)):
            for name in (None, *playback.durations):
                clicked, _ = imgui.selectable(_animation_label(playback, name), name == playback.animation)
                if clicked and name != playback.animation:
                    playback.choose(name)
            imgui.end_combo()
        changed, time = imgui.slider_float("Time", playback.time, 0.0, playback.duration, "%.2f s")
        if changed:
            playback.seek(time)
        changed, speed = imgui.slider_float("Speed", playback.speed, *SPEED_RANGE, "%.2fx",
                                            imgui.SliderFlags_.logarithmic)
        if changed:
            playback.speed = speed
        if imgui.button("Pause" if playback.playing else "Play", imgui.ImVec2(rect.width - LABEL_WIDTH, 0)):
            playback.playing = not playback.playing
        imgui.pop_item_width()
    imgui.end()


def _animation_label(playback, name):
    if name is None:
        return f"all ({max(playback.durations.values()):.1f} s)"
    return f"{name} ({playback.durations[name]:.1f} s)"


# ---- shader errors --------------------------------------------------------------------------

def draw_shader_errors(errors, window_size):
    """The current GLSL compile errors (file:line: message), until the file is fixed."""
    if not errors:
        return
    width = min(window_size[0] - 2 * MARGIN, 720)
    imgui.set_next_window_pos(imgui.ImVec2(window_size[0] / 2, window_size[1] - MARGIN), imgui.Cond_.always,
                              imgui.ImVec2(0.5, 1.0))
    imgui.set_next_window_size_constraints(imgui.ImVec2(width, 0), imgui.ImVec2(width, imgui.FLT_MAX))
    imgui.set_next_window_bg_alpha(0.85)
    flags = imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.always_auto_resize | imgui.WindowFlags_.no_saved_settings
    if imgui.begin("Shader error (last good program still running)", None, flags)[0]:
        imgui.push_text_wrap_pos(width - 2 * MARGIN)
        for message in errors:
            imgui.text_colored(ERROR_RED, message)
        imgui.pop_text_wrap_pos()
    imgui.end()
