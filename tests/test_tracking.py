"""Change tracking: a frame recomputes only what its inputs changed, found from the scene
itself, and its image is the image of a frame that recomputes everything."""
import moderngl
import numpy as np
import pytest

import engine
from conftest import SCENES, rel_mae
from engine.app.bench import FramePath, settle
from engine.scene.emitters import is_emissive

SIX = engine.RenderSettings(diffuse_cones="six")  # the cones the viewer converges with before refining

SCREEN_PASSES = ["gbuffer", "lighting", "cone_trace"]
BOUNCE_PASSES = {"gather", "faces", "mipmap"}


def settle_viewer(renderer, scene):
    """Progressive frames (the viewer) at grid 32 until the bounces settle; the last image."""
    renderer.progressive = True
    settle(scene, renderer, renderer.settings.replace(grid=32))
    assert renderer.settled
    return renderer.radiance()


def edits():
    """A sequence of scene edits, one per frame: (what it changes, the edit)."""
    def move_camera(scene):
        scene.camera.position = scene.camera.position + [0.05, -0.02, 0.0]

    def move_light(scene):
        scene.root.find("Omni Light").light.position = np.array([0.2, 0.6, -0.1])

    def edit_material(scene):
        scene.root.find("Tall Box").material.albedo = np.array([0.2, 0.5, 0.8])

    def move_object(scene):
        scene.root.find("Short Box").translation = scene.root.find("Short Box").translation + [0.1, 0.0, -0.05]

    return [("camera", move_camera), ("light", move_light), ("material", edit_material), ("object", move_object),
            ("camera", move_camera)]


def render_sequence(track_changes, progressive=False, grid=32, frames_per_edit=1):
    scene = engine.load_scene(SCENES / "cornell_box.json")
    images, passes = [], []
    with engine.Renderer(64, 64) as r:
        r.track_changes, r.progressive = track_changes, progressive
        images.append(r.render(scene, grid=grid))
        for _, edit in edits():
            edit(scene)
            for _ in range(frames_per_edit):
                images.append(r.render(scene, grid=grid))
                passes.append(list(r.passes_ran))
    return images, passes


def test_a_moved_object_redraws_only_the_shadow_views_that_see_it():
    """The Cornell box's omni light hangs 0.7 m above the centre; the short box stands on the
    floor: of the light's six cube faces only the one looking down sees it, before and after it
    moves, so that tile alone is drawn again (the frames stay those of a full recompute:
    test_tracked_frames_equal_recomputed_frames_bit_for_bit)."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64) as r:
        r.render(scene, grid=32, mode="direct")
        assert r.shadow.drawn_tiles == [0, 1, 2, 3, 4, 5]
        box = scene.root.find("Short Box")
        box.translation = box.translation + [0.1, 0.0, -0.05]
        r.render(scene, grid=32, mode="direct")
        assert r.shadow.drawn_tiles == [3]  # CUBE_FACES: +x, -x, +y, -y, +z, -z


def test_a_light_redraws_its_shadow_views_only_when_they_move():
    """A shadow tile holds the depths its view sees: the omni light turned twice as bright
    draws none of its cube faces again (its frame lit twice as brightly), moved it draws all six."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64) as r:
        before = r.render(scene, grid=32, mode="direct")
        lamp = scene.root.find("Omni Light").light
        lamp.intensity = lamp.intensity * 2.0
        brighter = r.render(scene, grid=32, mode="direct")
        assert r.shadow.drawn_tiles == [] and np.allclose(brighter, 2.0 * before, rtol=1e-5, atol=1e-7)
        lamp.position = lamp.position + [0.1, 0.0, 0.0]
        r.render(scene, grid=32, mode="direct")
        assert r.shadow.drawn_tiles == [0, 1, 2, 3, 4, 5]


def test_tracked_frames_equal_recomputed_frames_bit_for_bit():
    """Converged bounces: camera, light, material and object edits, each frame rendered with
    change tracking equals the same frame with every stage recomputed, bit for bit (integer
    voxel sums make a partial revoxelization identical to a full one)."""
    tracked, _ = render_sequence(track_changes=True)
    forced, _ = render_sequence(track_changes=False)
    for frame, (a, b) in enumerate(zip(tracked, forced)):
        assert np.array_equal(a, b), f"frame {frame} differs"


def test_each_kind_of_change_runs_only_the_passes_it_needs():
    """Camera moved: G-buffer, lighting and cone trace only. Light moved: its shadow map,
    injection and bounces, lighting, no voxelization, no G-buffer and no new class list.
    Material edited: revoxelization, injection and bounces, no shadow map. Object moved: all
    of them."""
    _, passes = render_sequence(track_changes=True)
    ran = dict(zip([kind for kind, _ in edits()], passes))
    assert passes[0] == SCREEN_PASSES and passes[-1] == SCREEN_PASSES
    assert {"shadow", "inject", "lighting"} <= set(ran["light"]) and BOUNCE_PASSES <= set(ran["light"])
    assert "voxelize" not in ran["light"] and "gbuffer" not in ran["light"]
    assert "classes" not in ran["light"]  # the voxels, and so their anchors and classes, are kept
    assert {"voxelize", "inject"} <= set(ran["material"]) and BOUNCE_PASSES <= set(ran["material"])
    assert "shadow" not in ran["material"]
    assert {"shadow", "voxelize", "inject", "classes"} <= set(ran["object"]) and BOUNCE_PASSES <= set(ran["object"])


def test_gather_anchors_found_again_around_a_moved_object_equal_anchors_found_anew():
    """After an object moves, the gather anchors are found again only around the voxels the
    voxelization touched; every covered voxel's anchors equal those found from scratch."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64) as tracked, engine.Renderer(64, 64) as fresh:
        tracked.render(scene, grid=32)
        box = scene.root.find("Short Box")
        box.translation = box.translation + [0.1, 0.0, -0.05]
        tracked.render(scene, grid=32)
        fresh.render(scene, grid=32)
        records = []
        for r in (tracked, fresh):
            lists = r.voxel_lists()
            voxels = [tuple(voxel) for voxel in lists.covered.tolist()]
            records.append((len(lists.touched), len(lists.covered), set(voxels), dict(zip(voxels, lists.anchors))))
    (touched, covered, voxels, found_again), (_, _, fresh_voxels, found_anew) = records
    assert 0 < touched < covered  # a partial voxelization
    assert voxels == fresh_voxels and found_again == found_anew


def test_tracked_frames_lit_by_an_emitter_equal_recomputed_frames_bit_for_bit():
    """A scene lit by an emissive panel: moving the camera, dimming the panel, moving it and
    moving a sphere under it, each frame rendered with change tracking equals the same frame
    with every stage recomputed, bit for bit (the emitters' triangles follow their draws, and
    their shadows the voxels)."""
    def dim_panel(scene):
        scene.root.find("Ceiling Panel").material.emission = np.array([6.0, 5.0, 4.0])

    def move_panel(scene):
        panel = scene.root.find("Ceiling Panel")
        panel.translation = panel.translation + [0.2, -0.1, 0.0]

    def move_sphere(scene):
        sphere = scene.root.find("Gold Sphere")
        sphere.translation = sphere.translation + [0.1, 0.05, 0.0]

    def move_camera(scene):
        scene.camera.position = scene.camera.position + [0.05, -0.02, 0.0]

    images = {}
    for track_changes in (True, False):
        scene = engine.load_scene(SCENES / "cornell_spheres.json")
        with engine.Renderer(64, 64) as r:
            r.track_changes = track_changes
            images[track_changes] = [r.render(scene, grid=32)]
            for edit in (move_camera, dim_panel, move_panel, move_sphere):
                edit(scene)
                images[track_changes].append(r.render(scene, grid=32))
    for frame, (a, b) in enumerate(zip(images[True], images[False])):
        assert np.array_equal(a, b), f"frame {frame} differs"
    assert images[True][2].mean() < 0.6 * images[True][1].mean()  # the dimmed panel lights the room less


def test_a_moved_emitter_in_the_viewer_relights_the_voxels_over_the_next_frames():
    """Progressive frames (the viewer): after the panel of cornell_spheres moves, the emitters'
    light at the voxels is recomputed one interleave class a frame (no frame pays for the whole
    grid), and the room converges to the headless image of the edited scene within 1 % (the
    lecture's six cones, with which the viewer converges before refining)."""
    scene = engine.load_scene(SCENES / "cornell_spheres.json")
    with engine.Renderer(64, 64, settings=SIX) as r:
        settle_viewer(r, scene)
        panel = scene.root.find("Ceiling Panel")
        panel.translation = panel.translation + [0.3, -0.2, 0.1]
        lit = []
        for _ in range(80):
            image = r.render(scene, grid=32)
            lit.append("emitter_light" in r.passes_ran)
        interleave = r.settings.bounce_interleave
    assert interleave > 1 and lit[:interleave] == [True] * interleave and not any(lit[interleave:])
    with engine.Renderer(64, 64, settings=SIX) as fresh:
        assert rel_mae(image, fresh.render(scene, grid=32)) < 0.01


def test_a_moved_light_in_the_viewer_relights_one_class_of_voxels_a_frame():
    """Progressive frames (the viewer): after the light moves, each frame injects the new
    direct light into one interleave class of the voxels, the class it bounces (a quarter of
    the lit voxels change in the first frame), every voxel carries it after K frames, and the
    room settles within 0.5 % of the image a new viewer of the edited scene settles on (the
    lecture's six cones)."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64, settings=SIX) as r:
        settle_viewer(r, scene)
        before = r.voxels("radiance")[..., :3]
        lit = np.any(before > 0, axis=-1)
        scene.root.find("Omni Light").light.position = np.array([0.2, 0.6, -0.1])
        changed, injected = [], []
        for _ in range(60):
            image = r.render(scene, grid=32)
            changed.append(np.mean(np.any(r.voxels("radiance")[..., :3] != before, axis=-1)[lit]))
            injected.append("inject" in r.passes_ran)
        interleave = r.settings.bounce_interleave
    assert interleave == 4 and injected[:interleave] == [True] * interleave and not any(injected[interleave:])
    assert 0.15 < changed[0] < 0.35 and changed[interleave - 1] > 0.95
    with engine.Renderer(64, 64, settings=SIX) as fresh:
        assert rel_mae(image, settle_viewer(fresh, scene)) < 0.005


def test_a_moved_object_in_the_viewer_carries_its_direct_light_at_once():
    """Progressive frames (the viewer): when an object moves, the voxels the voxelization
    touched (where it was and where it is) get their direct light in that frame, the same as
    a new render of the edited scene, while the rest of the grid, whose shadows moved, is relit
    one class a frame; the room settles within 0.5 % of where a new viewer settles."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    box = scene.root.find("Short Box")
    with engine.Renderer(64, 64) as r:
        settle_viewer(r, scene)
        before = r.voxels("radiance")
        box.translation = box.translation + [0.1, 0.0, -0.05]
        r.render(scene, grid=32)
        base = r.voxels("radiance")
        x, y, z = r.voxel_lists().touched.T
        touched = np.zeros(base.shape[:3], bool)
        touched[z, y, x] = True
        with engine.Renderer(64, 64) as fresh:
            fresh.render(scene, grid=32)
            expected = fresh.voxels("radiance")
        covered = r.voxels("albedo")[..., 3] > 0
        assert (touched & covered).sum() > 100
        assert np.array_equal(base[touched & covered], expected[touched & covered])
        shadow_moved = covered & ~touched & np.any(before != expected, axis=-1)
        assert shadow_moved.sum() > 50
        assert np.all(base == expected, axis=-1)[shadow_moved].mean() < 0.5  # relit a class a frame
        settle(scene, r, r.settings.replace(grid=32))
        image = r.radiance()
    with engine.Renderer(64, 64) as fresh:
        assert rel_mae(image, settle_viewer(fresh, scene)) < 0.005


def test_a_new_interleave_while_a_light_move_is_injected_relights_every_voxel():
    """The viewer's interleave changed while a moved light is still being injected class by
    class: the classes of the new interleave are all injected again, and the room settles on
    the image a new viewer of the edited scene settles on with that interleave."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64) as r:
        settle_viewer(r, scene)
        scene.root.find("Omni Light").light.position = np.array([0.2, 0.6, -0.1])
        r.render(scene, grid=32)
        settings = r.settings.replace(grid=32, bounce_interleave=3)
        settle(scene, r, settings)
        assert r.settled
        image = r.radiance()
    with engine.Renderer(64, 64) as fresh:
        fresh.progressive = True
        settle(scene, fresh, settings)
        assert rel_mae(image, fresh.radiance()) < 0.005


def test_progressive_tracked_frames_stay_within_a_percent_of_recomputed_frames():
    """Progressive bounces (the viewer): a tracked frame stops bouncing once the radiance has
    settled, a recomputing one keeps bouncing; after each edit has had 12 frames to converge
    the two images differ by under 1 % (relative MAE)."""
    tracked, _ = render_sequence(track_changes=True, progressive=True, frames_per_edit=12)
    forced, _ = render_sequence(track_changes=False, progressive=True, frames_per_edit=12)
    settled = [tracked[k] for k in range(12, len(tracked), 12)], [forced[k] for k in range(12, len(forced), 12)]
    for a, b in zip(*settled):
        assert rel_mae(a, b) < 0.01


def test_a_settled_progressive_frame_runs_no_bounce():
    """Once the progressive radiance settles, a frame where nothing moved runs the cone trace
    alone (the G-buffer and the direct light are kept): the viewer idles at less than the
    cost of a static frame."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64) as r:
        settle_viewer(r, scene)
        r.render(scene, grid=32)
        assert r.passes_ran == ["cone_trace"]


@pytest.mark.parametrize("edit", ["remove", "add"])
def test_objects_leaving_and_joining_the_scene_update_the_voxels(edit):
    """Removing a node (or adding one) revoxelizes just its voxels: the grid equals a fresh
    voxelization of the edited scene, and the GPU holds the meshes drawn, no others."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    root = scene.root
    short_box = root.find("Short Box")
    short_box.mesh = engine.scene.model.box_mesh()  # a mesh of its own, which leaves the GPU with it
    with engine.Renderer(64, 64) as r:
        if edit == "add":
            root.children.remove(short_box)
        r.render(scene, grid=32, bounces=1)
        if edit == "add":
            root.children.append(short_box)
        else:
            root.children.remove(short_box)
        image = r.render(scene, grid=32, bounces=1)
        voxels = [r.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")]
        assert r.held_meshes[0] == len({id(node.mesh) for node, _ in scene.drawables()})
    with engine.Renderer(64, 64) as fresh:
        assert np.array_equal(fresh.render(scene, grid=32, bounces=1), image)
        assert [fresh.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")] == voxels


def test_a_mesh_given_new_vertices_is_drawn_and_voxelized_anew():
    """Mesh arrays are read-only; giving a mesh a new positions array is an edit the renderer
    notices: the frame equals a fresh render of the edited scene."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    short_box = scene.root.find("Short Box")
    short_box.mesh = engine.scene.model.box_mesh()
    with engine.Renderer(64, 64) as r:
        r.render(scene, grid=32, bounces=1)
        with pytest.raises(ValueError):
            short_box.mesh.positions[0, 0] = 1.0
        short_box.mesh.positions = short_box.mesh.positions * [1.0, 1.5, 1.0]
        edited = r.render(scene, grid=32, bounces=1)
    with engine.Renderer(64, 64) as fresh:
        assert np.array_equal(fresh.render(scene, grid=32, bounces=1), edited)


def test_an_emission_edit_in_the_viewer_lights_the_room_over_the_next_frames():
    """The inspector turns the short box into a lamp while the viewer's bounces are settled:
    the next frame shows it glowing, and the room converges to the edited scene's image (24
    bounces) within 1 % as the progressive bounces carry its light (the lecture's six cones)."""
    from engine.app.viewer import inspector
    scene = engine.load_scene(SCENES / "cornell_box.json")
    with engine.Renderer(64, 64, settings=SIX) as r:
        before = settle_viewer(r, scene)
        inspector.make_material_unique(scene, "Short Box")
        inspector.set_emission(scene, "Short Box", [4.0, 4.0, 4.0])
        frames = [r.render(scene, grid=32) for _ in range(60)]
    with engine.Renderer(64, 64, settings=SIX) as r:
        expected = r.render(scene, grid=32, bounces=24)
    glowing = frames[0].mean(axis=2) > 4.0          # the box's own pixels, from the next frame on
    assert glowing.sum() > 100 and not (before.mean(axis=2) > 4.0).any()
    assert frames[0].mean() < frames[-1].mean()      # its light reaches the room over the frames
    assert rel_mae(frames[-1], expected) < 0.01


def test_a_stage_names_the_inputs_that_changed_since_it_last_ran():
    """Without GL: a stage that never ran, or runs untracked, sees every input as changed;
    after a run, only the inputs whose values differ (compared as tuples compare their items:
    the same object is unchanged)."""
    from engine.scene.changes import Stage

    stage = Stage()
    inputs = {"voxels": 3, "lights": ((1.0, 2.0),), "draws": (object(),)}
    assert stage.changed(inputs) == set(inputs) and stage.last("voxels") is None
    stage.ran(inputs)
    assert stage.version == 1 and not stage.changed(dict(inputs))
    assert stage.changed(dict(inputs, lights=((1.0, 2.5),))) == {"lights"}
    assert stage.changed(dict(inputs, voxels=4, draws=(object(),))) == {"voxels", "draws"}
    assert stage.changed(inputs, tracking=False) == set(inputs)
    stage.forget()
    assert stage.changed(inputs) == set(inputs)


@pytest.mark.parametrize("scene_file, kind", [("cornell_box.json", "camera"), ("cornell_box.json", "light"),
                                              ("cornell_box.json", "object"), ("cornell_spheres.json", "emitter"),
                                              ("city_block.json", "flight")])
def test_viewer_frames_read_back_nothing_but_the_totals_of_the_frame_before(scene_file, kind, monkeypatch):
    """Progressive frames (the viewer) from when the lecture's six cones converged, the tiled
    set refining the gathers, while the camera, a light, an object or an emitter moves, then on:
    the counts that size each pass stay on the GPU (indirect dispatches), so a frame reads
    nothing back from it except, at the start of the frame after a cycle of the bounce ends,
    the totals that cycle's end computed; and none waits for it with glFinish. Under a clipmap
    (the city block) a camera flying at walking speed scrolls the levels: the slabs they take
    in are bounded on the host, so a scroll reads nothing either."""
    scene = engine.load_scene(SCENES / scene_file)
    emitter = next(node for node, _ in scene.drawables() if is_emissive(node.material)) if kind == "emitter" else None
    path = FramePath(scene, {"camera": "static", "emitter": "static", "flight": "camera"}.get(kind, kind))
    with engine.Renderer(48, 48) as r:
        r.progressive = True
        settings = r.settings.replace(grid=32)
        for _ in range(200):
            r.render_frame(scene, settings)
            if r.refining:
                break
        assert r.refining
        reads = []
        for cls in (moderngl.Buffer, moderngl.Texture, moderngl.Texture3D):
            monkeypatch.setattr(cls, "read", lambda self, *a, _read=cls.read, **k: (reads.append(1), _read(self, *a, **k))[1])
        monkeypatch.setattr(moderngl.Context, "finish", lambda self: reads.append("finish"))
        frames = []
        for frame in range(40):
            if frame < 8:
                path.apply(frame)
                if emitter is not None:
                    emitter.translation = emitter.translation + [0.01, 0.0, 0.0]
            reads.clear()
            r.render_frame(scene, settings)
            frames.append((list(reads), "totals" in r.passes_ran, "voxelize" in r.passes_ran))
    assert any(requested for _, requested, _ in frames) or kind in ("camera", "flight")
    assert any(scrolled for _, _, scrolled in frames) or kind != "flight"
    for k, (frame_reads, _, _) in enumerate(frames):
        assert len(frame_reads) <= (1 if k > 0 and frames[k - 1][1] else 0), f"frame {k}: {frame_reads}"


def test_a_camera_flying_at_walking_speed_costs_the_screen_passes_alone():
    """vct bench's camera frames: the camera flies along its view at 1.4 m/s, 1/30 s a frame
    (4.7 cm), and turns back after a quarter of the scene's size; with one grid over the whole
    scene such a frame runs the G-buffer, the direct light and the cone trace, as a static one."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    path = FramePath(scene, "camera")
    home = scene.camera.position.copy()
    with engine.Renderer(32, 32) as r:
        r.progressive = True
        settings = r.settings.replace(grid=32)
        settle(scene, r, settings)
        steps = []
        for frame in range(1, 40):
            path.apply(frame)
            steps.append(float(np.linalg.norm(scene.camera.position - home)))
            r.render_frame(scene, settings)
            assert r.passes_ran == SCREEN_PASSES
    path.restore()
    lo, hi = scene.bounds()
    assert steps[0] == pytest.approx(1.4 / 30) and max(steps) <= 0.25 * float(np.max(hi - lo)) + 1e-9
    assert np.all(np.abs(np.diff(steps)) <= 1.4 / 30 + 1e-9) and steps[-1] < max(steps)
