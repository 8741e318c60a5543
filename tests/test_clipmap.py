"""Clipmaps: voxel levels centred on the camera for scenes larger than one grid. Each level is
a cube of N^3 voxels twice as large as the one inside it, on a lattice of its own voxels; cones
read the level whose voxels match their footprint and blend across the levels' borders; the
levels follow the camera; bad clipmaps are refused naming the field."""
import json

import numpy as np
import pytest

import engine
from engine.core.constants import FACING_EXPONENT
from engine.core.errors import SceneError
from engine.scene.model import Clipmap, VoxelRegion
from engine.voxels.clipmap import default_clipmap, entered_slabs, level_regions, level_shift, level_snap_voxels, moved_levels
from conftest import REFERENCE, SCENES, reference_file, rel_mae
from test_cli import assert_one_line_error, vct
from test_tracking import SCREEN_PASSES


def test_each_level_doubles_the_voxels_of_the_one_inside_it_and_holds_the_camera():
    clipmap = Clipmap(levels=5, resolution=32, voxel_size=0.04)
    eye = np.array([3.17, 1.52, -8.9])
    regions = level_regions(clipmap, eye)
    assert len(regions) == 5
    for k, region in enumerate(regions):
        voxel = 0.04 * 2 ** k
        assert region.size == pytest.approx(32 * voxel)
        corner = np.asarray(region.center) - region.size / 2
        lattice = corner / (level_snap_voxels(32) * voxel)
        np.testing.assert_allclose(lattice, np.round(lattice), atol=1e-9)  # on the level's own lattice
        assert np.all(np.abs(eye - region.center) <= level_snap_voxels(32) * voxel / 2 + 1e-9)  # centred on the camera
        if k:
            inner = regions[k - 1]
            assert np.all(np.abs(np.asarray(inner.center) - region.center) + inner.size / 2 <= region.size / 2)  # nested


def test_a_level_moves_only_when_the_camera_leaves_its_lattice_step():
    clipmap = Clipmap(levels=3, resolution=32, voxel_size=0.1)
    eye = np.array([0.05, 0.0, 0.0])
    before = level_regions(clipmap, eye)
    nudged = level_regions(clipmap, eye + [0.1, 0, 0])   # a quarter of level 0's step of 4 voxels
    moved = level_regions(clipmap, eye + [0.4, 0, 0])    # a whole step of level 0
    assert all(np.array_equal(a.center, b.center) for a, b in zip(before, nudged))
    assert moved[0].center[0] == pytest.approx(before[0].center[0] + 0.4)


def test_a_levels_lattice_step_is_an_eighth_of_it_and_at_least_its_mip_2_cells():
    """A level scrolls as often whatever its resolution, and its mip-2 cells stay on the next
    coarser level's mip-1 cells."""
    for n, step in ((16, 4), (32, 4), (64, 8), (256, 32)):
        clipmap = Clipmap(levels=2, resolution=n, voxel_size=0.1)
        eye = np.array([0.05, 0.0, 0.0])
        before = level_regions(clipmap, eye)
        within = level_regions(clipmap, eye + [0.1 * step * 0.25, 0, 0])
        past = level_regions(clipmap, eye + [0.1 * step, 0, 0])
        assert level_snap_voxels(n) == step
        assert np.array_equal(before[0].center, within[0].center)
        assert past[0].center[0] == pytest.approx(before[0].center[0] + 0.1 * step)


def test_the_default_clipmaps_coarsest_level_spans_twice_the_scene():
    clipmap = default_clipmap(4, 64, VoxelRegion(np.zeros(3), 10.0))
    assert clipmap.voxel_size * 2 ** 3 * 64 == pytest.approx(20.0)


def clipmap_file(tmp_path, clipmap, base="cornell_box.json", **extra):
    data = json.loads((SCENES / base).read_text())
    data["voxel_region"] = dict({"clipmap": clipmap}, **extra)
    path = tmp_path / "clipmap.json"
    path.write_text(json.dumps(data))
    return path


def test_a_scene_file_clipmap_is_read_into_the_scene(tmp_path):
    scene = engine.load_scene(clipmap_file(tmp_path, {"levels": 3, "resolution": 32, "voxel_size": 0.05}))
    assert scene.clipmap == Clipmap(3, 32, 0.05) and scene.voxel_region is None


@pytest.mark.parametrize("clipmap, extra, field, mention", [
    ({"levels": 0, "resolution": 32, "voxel_size": 0.05}, {}, "voxel_region.clipmap.levels", "at least 1"),
    ({"levels": 11, "resolution": 32, "voxel_size": 0.05}, {}, "voxel_region.clipmap.levels", "at most 10"),
    ({"levels": 3, "resolution": 48, "voxel_size": 0.05}, {}, "voxel_region.clipmap.resolution", "16, 32, 64, 128, 256"),
    ({"levels": 3, "resolution": 32, "voxel_size": 0}, {}, "voxel_region.clipmap.voxel_size", "positive"),
    ({"levels": 3, "resolution": 32, "voxel_size": -1}, {}, "voxel_region.clipmap.voxel_size", "positive"),
    ({"levels": 3, "resolution": 32}, {}, "voxel_region.clipmap.voxel_size", "missing"),
    ({"levels": 3, "resolution": 32, "voxel_size": 0.05, "centre": [0, 0, 0]}, {}, "voxel_region.clipmap", "unknown field"),
    ({"levels": 3, "resolution": 32, "voxel_size": 0.05}, {"size": 2.0}, "voxel_region.size", "not both"),
], ids=["levels-0", "levels-11", "resolution-48", "voxel-size-0", "voxel-size-negative", "no-voxel-size", "misspelled",
        "clipmap-and-size"])
def test_a_bad_clipmap_is_refused_naming_the_file_and_the_field(tmp_path, clipmap, extra, field, mention):
    path = clipmap_file(tmp_path, clipmap, **extra)
    with pytest.raises(SceneError) as info:
        engine.load_scene(path)
    message = str(info.value)
    assert str(path) in message and field in message and mention in message, message


def test_a_non_finite_voxel_size_is_refused(tmp_path):
    path = clipmap_file(tmp_path, {"levels": 3, "resolution": 32, "voxel_size": 0.05})
    path.write_text(path.read_text().replace('"voxel_size": 0.05', '"voxel_size": Infinity'))
    result = vct("render", path, "--out", tmp_path / "out.png")
    assert_one_line_error(result, path, "voxel_region.clipmap.voxel_size", "Infinity")
    assert not (tmp_path / "out.png").exists()


def test_a_clipmap_the_driver_cannot_hold_is_refused_before_anything_is_written(tmp_path):
    path = clipmap_file(tmp_path, {"levels": 10, "resolution": 256, "voxel_size": 0.05})
    result = vct("render", path, "--out", tmp_path / "out.png")
    assert_one_line_error(result, path, "voxel_region.clipmap", "10 levels")
    assert not (tmp_path / "out.png").exists()


def test_clipmap_option_out_of_range_is_refused(tmp_path):
    result = vct("render", SCENES / "cornell_box.json", "--clipmap", "11", "--out", tmp_path / "out.png")
    assert_one_line_error(result, "--clipmap", "at most 10")


@pytest.fixture(scope="module")
def small():
    with engine.Renderer(64, 64) as r:
        yield r


def test_a_clipmap_lights_the_cornell_box_as_the_path_tracer_does(renderer, cornell):
    """Two levels of 64^3: the finest holds the camera's half of the box in the voxels of a 64^3
    grid over it, the next the rest in voxels twice as wide. Within 0.07 of Mitsuba (relative
    mean absolute error; the 64^3 grid: 0.064) and 3 % of its brightness."""
    reference = np.load(reference_file(REFERENCE / "cornell_box_gi.npy"))
    cornell.clipmap = Clipmap(levels=2, resolution=64, voxel_size=2.1 / 64)
    image = renderer.render(cornell, mode="gi")
    assert renderer.voxel_layout.levels == 2 and renderer.voxel_layout.voxel_count == 2 * 64 ** 3
    assert rel_mae(image, reference) < 0.07
    assert image.mean() / reference.mean() == pytest.approx(1.0, abs=0.03)


def test_a_plane_under_a_uniform_sky_is_lit_alike_across_the_levels_borders(small, tmp_path):
    """An open floor sees the whole sky: L = rho L_sky = 1 wherever it is, whichever level's
    voxels its pixels and its sky cones read (three levels of 16^3, whose borders lie 0.8, 1.6
    and 3.2 m from the camera, all in view)."""
    floor = {"name": "Floor", "type": "quad", "material": "m", "vertices": [[-20, 0, 20], [20, 0, 20], [20, 0, -20], [-20, 0, -20]]}
    path = tmp_path / "floor.json"
    path.write_text(json.dumps({
        "camera": {"position": [0, 0.5, 0], "look_at": [0, 0, -1.5], "vertical_fov_deg": 90, "width": 64, "height": 64},
        "materials": {"m": {"albedo": [0.5, 0.5, 0.5]}}, "objects": [floor], "environment": {"radiance": [2, 2, 2]},
        "voxel_region": {"clipmap": {"levels": 3, "resolution": 16, "voxel_size": 0.1}}}))
    image = small.render(engine.load_scene(path), mode="gi")
    lit = image[40:, :].mean(axis=-1)  # the floor, from below the horizon to the camera's feet
    assert lit.mean() == pytest.approx(1.0, abs=0.04)
    assert np.abs(lit - 1.0).max() < 0.08
    assert np.abs(np.diff(lit, axis=0)).max() < 0.03  # no seam between rows


def test_a_coarser_levels_voxels_beneath_the_finer_level_take_the_gather_of_the_voxels_tiling_them(small, cornell):
    """Where level 0's cube holds a level-1 voxel, the 8 level-0 voxels that tile it hold the
    same surfaces in more detail: its gather is theirs, averaged with the weights the image
    gives voxels by how alike they face, G = sum_c W_c G_c / sum_c W_c."""
    cornell.clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    small.render(cornell, mode="gi", bounces=1)
    gathered, normals = small.voxels("gathered"), small.voxels("normal")
    fine, coarse = small.voxel_layout.regions
    n, voxel = 32, 0.05
    first_fine = np.rint((np.asarray(coarse.center) - coarse.size / 2 - (np.asarray(fine.center) - fine.size / 2)) / voxel).astype(int)
    checked = 0
    for z, y, x in zip(*np.nonzero(gathered[n:, ..., 3] > 0)):
        first = first_fine + 2 * np.array([x, y, z])
        if np.any(first < 0) or np.any(first > n - 2):
            continue  # not beneath level 0
        tile = (slice(first[2], first[2] + 2), slice(first[1], first[1] + 2), slice(first[0], first[0] + 2))
        g, m = gathered[tile].reshape(-1, 4), normals[tile].reshape(-1, 4)[:, :3]
        lit = g[:, 3] > 0
        unit = normals[n + z, y, x, :3] / np.linalg.norm(normals[n + z, y, x, :3])
        coherence = np.linalg.norm(m[lit], axis=1)
        weight = np.maximum(m[lit] @ unit / coherence, 0.0) ** FACING_EXPONENT * coherence
        if not lit.any() or weight.sum() <= 0:
            continue
        expected = (weight[:, None] * g[lit, :3]).sum(axis=0) / weight.sum()
        np.testing.assert_allclose(gathered[n + z, y, x, :3], expected, rtol=2e-2, atol=1e-3)
        checked += 1
    assert checked > 100


def test_after_the_camera_moves_the_image_is_the_one_a_new_renderer_makes_there(small, cornell):
    cornell.clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    small.render(cornell, mode="gi")
    cornell.camera.position = cornell.camera.position + np.array([0.3, -0.2, -0.9])
    moved = small.render(cornell, mode="gi")
    with engine.Renderer(64, 64) as fresh:
        expected = fresh.render(cornell, mode="gi")
    assert np.abs(moved - expected).mean() < 0.005 * expected.mean()


def test_a_level_scrolls_in_whole_voxels_and_takes_in_only_the_slabs_it_did_not_hold():
    """A level of 8^3 that moves by (3, 0, -2) voxels keeps the voxels its two cubes share and
    takes in the rest as disjoint slabs: together, every voxel of the new cube it did not hold."""
    held = VoxelRegion(np.array([0.4, 0.4, 0.4]), 0.8)
    region = VoxelRegion(np.array([0.7, 0.4, 0.2]), 0.8)
    shift = level_shift(held, region, 8)
    assert shift == (3, 0, -2)
    taken = np.zeros((8, 8, 8), int)
    for lo, hi in entered_slabs(shift, 8):
        taken[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] += 1
    x, _, z = np.indices((8, 8, 8))
    kept = (x + 3 < 8) & (z - 2 >= 0)  # new coordinates whose old ones lay in the old cube
    assert np.array_equal(taken, (~kept).astype(int))
    assert level_shift(held, VoxelRegion(np.array([1.2, 0.4, 0.4]), 0.8), 8) is None  # a whole cube: nothing kept


def test_a_level_that_moves_scrolls_and_holds_the_voxels_a_new_grid_there_holds(small, cornell):
    """The camera moves along all three axes: both levels scroll, each voxelizing only the slabs
    it took in (its kept voxels keep their records), and the voxels are those a new grid placed
    there holds (all but a few voxels where surfaces meet on a voxel's edge), as is the image."""
    clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    cornell.clipmap = clipmap
    eye, step = np.array([-0.15, 0.0, 1.5]), np.array([0.61, -0.2, -0.43])
    cornell.camera.position = eye
    small.render(cornell, mode="gi")
    held = small.voxel_layout.regions
    cornell.camera.position = eye + step
    moved = small.render(cornell, mode="gi")
    shifts = [level_shift(a, b, 32) for a, b in zip(held, small.voxel_layout.regions)]
    assert all(shift is not None and any(shift) for shift in shifts)
    in_slabs = np.zeros((2 * 32, 32, 32), bool)  # [level z, y, x]
    for level, shift in enumerate(shifts):
        for lo, hi in entered_slabs(shift, 32):
            in_slabs[32 * level + lo[2]:32 * level + hi[2], lo[1]:hi[1], lo[0]:hi[0]] = True
    x, y, z = small.voxel_lists().touched.T
    assert len(x) > 0 and in_slabs[z, y, x].all()  # the slabs' voxels, no others
    with engine.Renderer(64, 64) as fresh:
        expected = fresh.render(cornell, mode="gi")
        for name in ("albedo", "normal", "radiance"):
            differ = np.any(small.voxels(name) != fresh.voxels(name), axis=-1)
            assert differ.sum() <= 4, name
    assert np.abs(moved - expected).mean() < 0.005 * expected.mean()


def test_an_object_that_moves_in_a_clipmap_leaves_each_level_as_a_new_grid_holds_it(small, cornell):
    """The short box moves: only its voxels are rebuilt, in each level that holds it within a
    voxel of that level, and every level is the bits a fresh voxelization makes."""
    cornell.clipmap = Clipmap(levels=3, resolution=16, voxel_size=0.05)
    small.render(cornell, mode="gi", bounces=1)
    cornell.root.find("Short Box").translation += [0.1, 0.0, 0.15]
    moved = small.render(cornell, mode="gi", bounces=1)
    with engine.Renderer(64, 64) as fresh:
        expected = fresh.render(cornell, mode="gi", bounces=1)
        for name in ("albedo", "normal", "radiance"):
            assert np.array_equal(small.voxels(name), fresh.voxels(name)), name
    assert np.array_equal(moved, expected)


def test_a_level_that_moves_alone_relights_its_voxels_and_the_coarser_ones_beneath_it_from_the_sky(small):
    """Under a sky, level 0 steps along x: its voxels take the sky's light again, and so do the
    coarser level's (its cones never read the finer level, but its voxels beneath level 0 take
    their light from the level-0 voxels tiling them, and which lie beneath it changed): the
    voxels' light and the image are the bits a new renderer makes there."""
    scene = engine.load_scene(SCENES / "references" / "open_box_sky.json")
    clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    scene.clipmap = clipmap
    eye = np.array([-0.15, 0.0, 0.95])
    step = np.array([level_snap_voxels(clipmap.resolution) * clipmap.voxel_size, 0.0, 0.0])
    assert moved_levels(level_regions(clipmap, eye), level_regions(clipmap, eye + step)) == {0}
    scene.camera.position, scene.camera.look_at = eye, eye + [0.0, 0.0, -1.9]
    small.render(scene, mode="gi")
    scene.camera.position, scene.camera.look_at = eye + step, eye + step + [0.0, 0.0, -1.9]
    moved = small.render(scene, mode="gi")
    with engine.Renderer(64, 64) as fresh:
        expected = fresh.render(scene, mode="gi")
        assert np.array_equal(small.voxels("radiance"), fresh.voxels("radiance"))  # the sky's light in it
    assert np.array_equal(moved, expected)


def test_in_the_viewer_a_scrolled_level_takes_in_the_coarser_levels_light_until_the_camera_rests(small):
    """Progressive frames under a sky, level 0 steps along x: in that frame the voxels it kept
    hold the light they had (the bits of before, at their new coordinates) and those it took in
    are lit as level 1 holds the sky's light at their surfaces, within 10 % of a new renderer's;
    once the camera rests, a round of the interleave classes lights level 0 with its own cones,
    and the voxels are a new renderer's bits."""
    scene = engine.load_scene(SCENES / "references" / "open_box_sky.json")
    scene.clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    eye, step = np.array([-0.15, 0.0, 0.95]), np.array([level_snap_voxels(32) * 0.05, 0.0, 0.0])
    n, shift = 32, level_snap_voxels(32)

    def frames_at(renderer, position, count):
        scene.camera.position, scene.camera.look_at = position, position + [0.0, 0.0, -1.9]
        for _ in range(count):
            renderer.render(scene)
        return renderer.voxels("radiance")[:n]  # level 0

    rest = 2 * small.settings.bounce_interleave
    small.progressive = True
    try:
        before = frames_at(small, eye, rest)
        moved = frames_at(small, eye + step, 1)
        with engine.Renderer(64, 64) as fresh:
            fresh.progressive = True
            expected = frames_at(fresh, eye + step, rest)
        assert np.array_equal(moved[:, :, :n - shift], before[:, :, shift:])
        taken, taken_expected = moved[:, :, n - shift:, :3], expected[:, :, n - shift:, :3]
        assert taken_expected.max() > 0 and np.abs(taken - taken_expected).mean() < 0.1 * taken_expected.mean()
        assert not np.array_equal(moved, expected)
        assert np.array_equal(frames_at(small, eye + step, rest), expected)
    finally:
        small.progressive = False


def test_the_viewer_moves_one_level_a_frame_finest_first(small, cornell):
    """Progressive frames bound the voxelization a camera move costs: each frame the finest
    level not yet where the camera wants it goes there, the others keep their voxels."""
    cornell.clipmap = Clipmap(levels=3, resolution=16, voxel_size=0.05)
    small.progressive = True
    small.render(cornell, mode="gi")
    start = level_regions(cornell.clipmap, cornell.camera.position)
    cornell.camera.position = cornell.camera.position + np.array([0.0, 0.0, -1.0])
    target = level_regions(cornell.clipmap, cornell.camera.position)
    assert moved_levels(start, target) == {0, 1, 2}
    for frame in range(3):
        small.render(cornell, mode="gi")
        assert moved_levels(small.voxel_layout.regions, target) == set(range(frame + 1, 3))
        assert moved_levels(small.voxel_layout.regions, start) == set(range(frame + 1))


def test_the_voxel_views_show_one_level_at_a_time(small, cornell):
    """From the camera at the box's open side, level 0 (1.6 m across) holds only the walls'
    front parts and level 1 (3.2 m) most of the box: each view shows its own level's voxels, with
    their albedo; a level the grid does not hold is refused naming the setting."""
    cornell.clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    views = [small.render(cornell, mode="voxel-albedo", voxel_level=level) for level in (0, 1)]
    shown = [view.max(axis=-1) > 0 for view in views]
    assert 0 < shown[0].mean() < 0.2 < shown[1].mean()
    assert all(0.6 < view[mask].max() <= 0.8 for view, mask in zip(views, shown))  # white walls: 0.73
    with pytest.raises(engine.VctError, match="level"):
        small.render(cornell, mode="voxel-albedo", voxel_level=2)


def test_the_clipmap_option_places_levels_of_the_grid_size_around_the_camera(small, cornell):
    small.render(cornell, mode="voxels", grid=32, clipmap_levels=4)
    assert small.voxel_layout.levels == 4 and small.voxel_layout.n == 32
    assert small.voxel_layout.level_voxel_size(3) == pytest.approx(8 * small.voxel_layout.level_voxel_size(0))


def test_clipmap_zero_gives_one_grid_where_the_scene_file_gives_a_clipmap(small, cornell):
    cornell.clipmap = Clipmap(levels=3, resolution=32, voxel_size=0.05)
    small.render(cornell, mode="voxels", grid=32)
    assert small.voxel_layout.levels == 3
    small.render(cornell, mode="voxels", grid=32, clipmap_levels=0)
    assert small.voxel_layout.levels == 1 and small.voxel_layout.level_voxel_size(0) == pytest.approx(cornell.region().size / 32)


def test_bench_reports_a_clipmaps_levels_voxels_and_memory_for_every_frame_kind(tmp_path):
    """`vct bench --clipmap 2 --grids 64`: each record names the levels and their voxels, at
    most 80 bytes a voxel (two sides of values per covered voxel: 70)."""
    result = vct("bench", SCENES / "cornell_box.json", "--clipmap", "2", "--grids", "64", "--frames", "4", "--warmup", "0",
                 "--width", "32", "--height", "32", "--quiet", "--json", tmp_path / "bench.json")
    assert result.returncode == 0, result.stderr
    records = {r["frame"]: r for r in json.loads((tmp_path / "bench.json").read_text())}
    assert set(records) == {"static", "camera", "light", "object"}
    for record in records.values():
        assert record["levels"] == 2 and record["voxel_count"] == 2 * 64 ** 3
        assert 0 < record["voxel_bytes_per_voxel"] <= 80
    assert "64^3 x 2" in result.stdout


def test_bench_times_a_scene_files_clipmap_once_at_its_own_resolution(tmp_path):
    """A scene file's clipmap keeps its resolution whatever `--grids` asks: the bench names the
    levels it timed (16^3 x 2), once, not the grids asked for."""
    data = json.loads((SCENES / "cornell_box.json").read_text())
    data["voxel_region"] = {"clipmap": {"levels": 2, "resolution": 16, "voxel_size": 0.05}}
    scene = tmp_path / "clipmapped.json"
    scene.write_text(json.dumps(data))
    result = vct("bench", scene, "--grids", "16,32", "--frames", "1", "--warmup", "0", "--width", "16", "--height", "16",
                 "--quiet", "--json", tmp_path / "bench.json")
    assert result.returncode == 0, result.stderr
    records = json.loads((tmp_path / "bench.json").read_text())
    assert {(r["grid"], r["levels"]) for r in records} == {(16, 2)} and len(records) == 4
    assert "16^3 x 2" in result.stdout and "32^3" not in result.stdout


def test_a_flying_camera_in_a_clipmap_lights_the_slabs_it_takes_in_and_restarts_no_bounce(small):
    """Progressive frames under a sky once the radiance settled, the camera flying along x:
    a frame that scrolls a level traces the light of the voxels it took in alone, and keeps
    the bounces settled, so the frames between scrolls run the screen passes alone, as with
    one grid."""
    scene = engine.load_scene(SCENES / "references" / "open_box_sky.json")
    scene.clipmap = Clipmap(levels=2, resolution=32, voxel_size=0.05)
    eye = np.array([-0.15, 0.0, 0.95])
    small.progressive = True
    try:
        for _ in range(400):
            scene.camera.position, scene.camera.look_at = eye, eye + [0.0, 0.0, -1.9]
            small.render(scene)
            if small.idle:
                break
        assert small.idle
        scrolls, between = 0, []
        for step in range(1, 13):  # 2 cm a frame: level 0 (4 voxels of 5 cm a lattice step) scrolls every 10
            position = eye + [0.02 * step, 0.0, 0.0]
            scene.camera.position, scene.camera.look_at = position, position + [0.0, 0.0, -1.9]
            small.render(scene)
            if "voxelize" in small.passes_ran:
                scrolls += 1
                assert small.settled
            else:
                between.append(list(small.passes_ran))
        assert scrolls >= 1 and between and all(ran == SCREEN_PASSES for ran in between)
    finally:
        small.progressive = False
