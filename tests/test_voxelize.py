"""Voxelization: a watertight, deterministic grid of radiance, normals and albedo, with
hardware mipmaps, built from the scene every frame."""
import numpy as np
import pytest

import engine
from engine.core.constants import VOXEL_SIDES
from engine.voxels import grid as voxel_grid
from conftest import SCENES


def voxel_index(renderer, point):
    """Index (x, y, z) of the voxel holding a world point in the renderer's last grid."""
    region, n = renderer.voxel_layout.regions[0], renderer.voxel_layout.n
    lo = np.asarray(region.center) - region.size / 2.0
    return tuple(int(i) for i in np.floor((np.asarray(point) - lo) / (region.size / n)))


def at(volume, index):
    x, y, z = index
    return volume[z, y, x]


@pytest.fixture
def voxels64(renderer):
    """The Cornell box at 64^3 (the renderer's last grid, so voxel_index applies)."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    renderer.render(scene, mode="voxels", grid=64)
    return {name: renderer.voxels(name) for name in ("radiance", "normal", "albedo")}


def test_voxel_size_follows_region_and_grid(renderer):
    """Voxel size = region size / N: the lecture's 2.56-unit region gives 0.01 at 256^3."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    scene.voxel_region = engine.scene.model.VoxelRegion(np.zeros(3), 2.56)
    renderer.render(scene, mode="voxels", grid=16)
    assert renderer.voxel_layout.voxel_size == pytest.approx(0.16)
    assert 2.56 / 256 == pytest.approx(0.01)


def test_voxelizing_twice_is_bit_identical(renderer):
    """Order-independent fixed-point averaging: the same scene gives the same bits."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    first, second = [], []
    for out in (first, second):
        renderer.render(scene, mode="voxels", grid=32)
        out += [renderer.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")]
    assert first == second


@pytest.mark.parametrize("grid", [32, 64])
def test_walls_are_watertight(renderer, grid):
    """Every ray crossing a wall plane along its normal meets at least one opaque voxel."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    renderer.render(scene, mode="voxels", grid=grid)
    opaque = renderer.voxels("radiance")[..., 3] > 0  # [z, y, x]
    inner = [voxel_index(renderer, (c, c, c))[0] for c in (-0.99, 0.99)]
    span = slice(inner[0], inner[1] + 1)
    for axis, name in ((2, "x"), (1, "y"), (0, "z")):
        for side in (-1.0, 1.0):
            wall = voxel_index(renderer, (side,) * 3)[0]
            layers = slice(max(wall - 1, 0), min(wall + 2, grid))  # the wall's voxel and its neighbours
            hit = np.take(opaque, range(layers.start, layers.stop), axis=axis).any(axis=axis)
            assert hit[span, span].all(), f"hole in the {name} = {side} wall at grid {grid}"


def test_left_wall_voxels_are_red_and_face_plus_x(renderer, voxels64):
    index = voxel_index(renderer, (-1.0, 0.0, 0.0))
    albedo = at(voxels64["albedo"], index)
    normal = at(voxels64["normal"], index)
    assert albedo[3] == 1.0
    assert np.allclose(albedo[:3], [0.65, 0.05, 0.05], atol=0.01)
    assert np.allclose(normal[:3], [1.0, 0.0, 0.0], atol=0.02)


def test_box_interior_is_empty(renderer, voxels64):
    """Only surfaces are voxelized: the inside of the tall box holds no voxel."""
    center = np.array([-0.35, -0.4, -0.4])
    lo = voxel_index(renderer, center - [0.15, 0.45, 0.15])
    hi = voxel_index(renderer, center + [0.15, 0.45, 0.15])
    inside = voxels64["radiance"][lo[2]:hi[2] + 1, lo[1]:hi[1] + 1, lo[0]:hi[0] + 1, 3]
    assert inside.size > 0 and not inside.any()


def test_mip_levels_are_the_mean_of_their_children(renderer):
    """Hardware mipmaps: level k+1 equals the mean of its 8 children of level k within
    8-bit rounding (premultiplied, so empty children lower opacity, not colour)."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    renderer.render(scene, mode="voxels", grid=32)
    for name in ("radiance", "normal"):
        for level in (0, 2):
            fine = renderer.voxels(name, level)
            coarse = renderer.voxels(name, level + 1)
            n = fine.shape[0] // 2
            mean = fine.reshape(n, 2, n, 2, n, 2, 4).mean(axis=(1, 3, 5))
            scale = max(1.0, float(np.abs(fine).max()))
            assert np.abs(coarse - mean).max() <= scale / 255.0, (name, level)
    top = renderer.voxels("radiance", 5)
    assert top.shape == (1, 1, 1, 4) and 0.0 < top[0, 0, 0, 3] < 1.0


def test_floor_voxel_under_the_light_holds_the_direct_radiance(renderer, voxels64):
    """The voxel's radiance is the surface's direct radiance: k_d/pi * I cos / d^2, the same
    value the G-buffer pass computes at that point (within 10%)."""
    expected = 0.73 / np.pi * 3.0 / 1.7 ** 2
    index = voxel_index(renderer, (0.0, -1.0, 0.0))
    voxel = at(voxels64["radiance"], index)
    assert voxel[3] == 1.0
    assert voxel[:3] == pytest.approx([expected] * 3, rel=0.10)


def test_voxel_in_the_tall_box_shadow_gets_no_direct_light(renderer, voxels64):
    shadowed = at(voxels64["radiance"], voxel_index(renderer, (-0.8, -1.0, -0.9)))
    lit = at(voxels64["radiance"], voxel_index(renderer, (0.0, -1.0, 0.0)))
    assert shadowed[3] == 1.0
    assert shadowed[:3].max() < 0.01 * lit[:3].max()


def test_voxel_view_shows_the_coloured_walls(renderer):
    scene = engine.load_scene(SCENES / "cornell_box.json")
    image = renderer.render(scene, mode="voxels", grid=64)
    left, right = image[40, 3], image[128, 252]
    assert left[0] > 3 * left[1] and right[1] > 2 * right[0]
    normals = renderer.render(scene, mode="voxel-normals", grid=64) * 2.0 - 1.0
    assert np.allclose(normals[60, 200], [0.0, 0.0, 1.0], atol=0.05)
    albedo = renderer.render(scene, mode="voxel-albedo", grid=64, voxel_mip=1)
    assert np.allclose(albedo[60, 200], [0.73] * 3, atol=0.02)


def test_impossible_grid_sizes_are_refused_before_allocation(renderer, monkeypatch):
    for grid in (8, 48, 512):
        with pytest.raises(engine.VctError, match="grid"):
            voxel_grid.check_grid(renderer.ctx, grid)
    monkeypatch.setattr(voxel_grid, "VOXEL_MEMORY_BUDGET", voxel_grid.voxel_memory_bytes(64))
    with pytest.raises(engine.VctError, match="GiB"):
        voxel_grid.check_grid(renderer.ctx, 128)
    voxel_grid.check_grid(renderer.ctx, 64)


def test_moving_an_object_leaves_no_stale_voxels(renderer):
    """Voxels are rebuilt every frame: after the short box moves, the grid (and the face views
    cones read) equals a fresh voxelization of the moved scene, bit for bit."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    renderer.render(scene, mode="gi", grid=32, bounces=1)
    scene.root.find("Short Box").translation += [0.0, 0.25, 0.0]
    renderer.render(scene, mode="gi", grid=32, bounces=1)
    moved = [renderer.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")]
    moved_image = renderer.radiance()
    with engine.Renderer(256, 256) as fresh:
        fresh_image = fresh.render(scene, mode="gi", grid=32, bounces=1)
        assert [fresh.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")] == moved
    assert np.array_equal(moved_image, fresh_image)


def test_voxel_memory_is_what_the_grid_holds_with_light_arrays_only_where_the_scene_has_that_light():
    """The voxel memory a renderer reports (vct bench, the viewer's overlay) is the GPU bytes its
    grid and passes hold: a scene under a sky holds two arrays of values more than the Cornell
    box (the sky's irradiance at the voxels, traced and filtered: an RGBA16F value for each
    side of each covered voxel the lists have room for), released when the sky goes; a voxel
    view adds an n^3 volume with its mip chain."""
    cornell = engine.load_scene(SCENES / "cornell_box.json")
    sky = engine.load_scene(SCENES / "references" / "open_box_sky.json")
    with engine.Renderer(16, 16) as r:
        r.render(cornell, grid=32, bounces=1)
        alone = r.voxel_memory_bytes()
        values = 8 * VOXEL_SIDES * r.voxel_layout.list_room
        r.render(sky, grid=32, bounces=1)
        assert r.voxel_memory_bytes() - alone == 2 * values
        r.render(cornell, grid=32, bounces=1)
        assert r.voxel_memory_bytes() == alone
        r.render(cornell, grid=32, mode="voxel-albedo", voxel_mip=1)
        assert r.voxel_memory_bytes() - alone == pytest.approx(8 * 32 ** 3 * 8 / 7, abs=16)
    assert alone < voxel_grid.voxel_memory_bytes(32)


def shelved(scene, heights):
    """`scene` (the Cornell box) with white shelves across the box at the given heights."""
    white = next(node.material for node, _ in scene.root.walk() if node.name == "Bottom Plane")
    for k, y in enumerate(heights):
        corners = [[-0.95, y, -0.95], [-0.95, y, 0.95], [0.95, y, 0.95], [0.95, y, -0.95]]
        scene.root.children.append(engine.Node(f"Shelf {k}", mesh=engine.scene.model.quad_mesh(corners), material=white))
    return scene


def test_voxel_lists_grow_to_hold_every_covered_voxel(renderer):
    """The voxel lists have room for what a grid covers, with a margin; shelves across the box
    cover more voxels than the box's walls. The update adding them outgrows the lists, which
    grow (and the record pool, which ran short with them): the grid and image equal a fresh
    voxelization of the shelved box, bit for bit, each covered voxel holds a record of its own,
    and a shelf moved afterwards updates the grown grid as a fresh one."""
    def state(r):
        return [r.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")], r.radiance()

    scene = engine.load_scene(SCENES / "cornell_box.json")
    renderer.render(scene, mode="gi", grid=32, bounces=1)
    room = renderer.voxel_layout.list_room
    walls = np.count_nonzero(renderer.voxels("albedo")[..., 3])
    shelved(scene, np.linspace(-0.9, 0.9, 15))
    for step in range(2):
        renderer.render(scene, mode="gi", grid=32, bounces=1)
        voxels, image = state(renderer)
        covered = np.count_nonzero(renderer.voxels("albedo")[..., 3])
        assert covered > room > walls and renderer.voxel_layout.list_room >= covered
        with engine.Renderer(256, 256) as fresh:
            fresh.render(scene, mode="gi", grid=32, bounces=1)
            fresh_voxels, fresh_image = state(fresh)
        assert voxels == fresh_voxels and np.array_equal(image, fresh_image)
        check_records(renderer)
        scene.root.find("Shelf 7").translation += [0.0, 0.05, 0.0]


def test_a_draw_covers_no_more_voxels_than_its_fragment_bound():
    """The host bounds the voxels a draw covers by its triangles' projected pixels (what lets a
    moved object be voxelized without reading a count back): every draw of the spheres' box,
    walls, boxes and tessellated spheres, voxelized alone over the same region, covers at most
    that many voxels, and the bound is within an order of magnitude of what it covers."""
    from engine.scene.table import SceneTable
    from engine.voxels.room import fragment_bound

    scene = engine.load_scene(SCENES / "cornell_spheres.json")
    scene.voxel_region = scene.region()
    table = SceneTable()
    table.sync(scene)
    draws = [table.draw(index) for index in range(table.draw_count)]
    with engine.Renderer(16, 16) as r:
        for draw in draws:
            alone = engine.Scene("alone", engine.Node("root", children=[draw.node]), scene.camera,
                                 voxel_region=scene.voxel_region)
            r.render(alone, mode="voxels", grid=32)
            covered = np.count_nonzero(r.voxels("albedo")[..., 3])
            bound = fragment_bound(draw, r.voxel_layout.bounds()[0], r.voxel_layout.voxel_size, r.voxel_layout.n)
            assert 0 < covered <= bound < 16 * covered, draw.node.name


def test_a_surface_that_starts_to_emit_lights_the_scene_as_if_it_always_had():
    """The emission volume the specular cones read is held only while some surface emits: the
    spheres' box with its lamps dark holds that volume less (from mip level 1 up, (n/2)^3 and
    coarser); lit again, its image is the one a fresh renderer makes, bit for bit (the volume
    is filled from the voxels already held)."""
    scene = engine.load_scene(SCENES / "cornell_spheres.json")
    lamps = [node.material for node, _ in scene.drawables() if np.any(node.material.emission > 0)]
    glow = [material.emission.copy() for material in lamps]
    with engine.Renderer(64, 64) as r:
        r.render(scene, grid=32, bounces=1)
        lit = r.voxel_memory_bytes()
        for material in lamps:
            material.emission = np.zeros(3)
        r.render(scene, grid=32, bounces=1)
        assert lit - r.voxel_memory_bytes() >= 8 * 16 ** 3
        for material, emission in zip(lamps, glow):
            material.emission = emission
        image = r.render(scene, grid=32, bounces=1)
        assert r.voxel_memory_bytes() == lit
    with engine.Renderer(64, 64) as fresh:
        assert np.array_equal(image, fresh.render(scene, grid=32, bounces=1))


def test_voxels_summed_in_chunks_are_the_voxels_summed_at_once(monkeypatch):
    """The voxelizer's sums hold a chunk of the touched voxels at a time; the shelved box at
    32^3 touches more than two chunks' worth. Summed chunk after chunk, or all at once with
    room enough, the grid and the image are the same bits."""
    scene = shelved(engine.load_scene(SCENES / "cornell_box.json"), np.linspace(-0.9, 0.9, 15))
    chunk = voxel_grid.sum_room(32, 1)
    results = []
    for room in (voxel_grid.SUM_ROOM, 32):
        monkeypatch.setattr(voxel_grid, "SUM_ROOM", room)
        with engine.Renderer(64, 64) as r:
            image = r.render(scene, mode="gi", grid=32, bounces=1)
            touched = len(r.voxel_lists().touched)
            results.append(([r.voxels(name).tobytes() for name in ("radiance", "normal", "albedo")], image, touched))
    (chunked, chunked_image, touched), (whole, whole_image, _) = results
    assert touched > 2 * chunk and voxel_grid.sum_room(32, 1) == 32 ** 3
    assert chunked == whole and np.array_equal(chunked_image, whole_image)


@pytest.mark.parametrize("sum_room", [voxel_grid.SUM_ROOM, 1])
def test_every_covered_voxel_holds_a_record_of_its_own_and_an_emptied_voxel_gives_it_back(monkeypatch, sum_room):
    """Per-voxel values live in records (engine/voxels/records.py): as the short box moves about,
    its updates summed at once or in chunks of 1024 voxels, each covered voxel holds one record
    no other voxel holds, no empty voxel holds one, and every other record is free in the pool."""
    monkeypatch.setattr(voxel_grid, "SUM_ROOM", sum_room)
    scene = engine.load_scene(SCENES / "cornell_box.json")
    box = scene.root.find("Short Box")
    with engine.Renderer(32, 32) as renderer:
        renderer.render(scene, mode="gi", grid=32, bounces=1)
        for step in ((0.3, 0.0, 0.0), (0.0, 0.2, -0.3), (-0.3, -0.2, 0.3)):
            box.translation += step
            renderer.render(scene, mode="gi", grid=32, bounces=1)
            check_records(renderer)


def check_records(renderer):
    """The record invariants of the renderer's grid (see the test above)."""
    lists, room, n = renderer.voxel_lists(), renderer.voxel_layout.list_room, renderer.voxel_layout.n
    x, y, z = lists.covered.T  # the covered list holds the voxel of each record
    held = lists.index[x + n * (y + n * z)]
    assert np.array_equal(held - 1, lists.records) and np.count_nonzero(lists.index) == len(lists.covered)
    assert lists.short == 0 and len(lists.free) == room - len(lists.covered)
    assert sorted(np.concatenate([held - 1, lists.free]).tolist()) == list(range(room))


def draped_cloth(scene, radius=0.5, gap=0.01, segments=24):
    """`scene` (the Cornell box) with a cloth of two sheets `gap` apart back to back, bent
    around the y axis from 75 to 15 degrees below +x towards -z (a banner's fold): its outer
    face's normal turns from mostly -z through the diagonal to mostly +x."""
    white = next(node.material for node, _ in scene.root.walk() if node.name == "Bottom Plane")
    angles = np.radians(np.linspace(-75.0, -15.0, segments + 1))
    for name, r, outward in (("Cloth front", radius, True), ("Cloth back", radius - gap, False)):
        ring = np.stack([r * np.cos(angles), np.zeros_like(angles), r * np.sin(angles)], axis=1)
        positions = np.concatenate([ring + [0.0, -0.3, 0.0], ring + [0.0, 0.3, 0.0]])
        k = np.arange(segments)
        quads = np.stack([k, k + 1, k + 1 + segments + 1, k + segments + 1], axis=1)
        triangles = np.concatenate([quads[:, [0, 2, 1]], quads[:, [0, 3, 2]]]) if outward else \
            np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
        scene.root.children.append(engine.Node(name, mesh=engine.triangle_mesh(positions, triangles), material=white))
    return scene


def test_a_draped_cloth_keeps_its_two_faces_apart_where_its_normal_crosses_a_diagonal(renderer):
    """Banners and curtains are two sheets back to back, draped: where a face's normal turns
    through the diagonal between two axes, the sign of its dominant component flips along it.
    The voxelizer sorts a voxel's fragments by facing with or against the facing most of them
    have, so each voxel on the cloth (two sheets 1 cm apart, inside one 6 cm voxel) keeps each
    face whole on a side of its own: side 0's mean normal stays coherent in every voxel on it
    (|n| > 0.9; measured 0.999 and up over 42 voxels. Sorted by that sign, the voxels where the
    normal crossed the diagonal mixed both faces in each orientation: 6 of them below 0.9, down
    to 0.08, their light cancelled)."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    scene.root.children = [node for node in scene.root.children if not node.name.endswith("Box")]
    draped_cloth(scene)
    renderer.render(scene, mode="voxels", grid=32)
    normal = renderer.voxels("normal")
    layout = renderer.voxel_layout
    lo, _ = layout.level_bounds(0)
    z, y, x = np.nonzero(normal[..., 3])
    centres = lo + (np.stack([x, y, z], axis=1) + 0.5) * layout.voxel_size
    radius, angle = np.hypot(centres[:, 0], centres[:, 2]), np.degrees(np.arctan2(centres[:, 2], centres[:, 0]))
    on_cloth = (np.abs(radius - 0.495) < 0.6 * layout.voxel_size) & (np.abs(centres[:, 1]) < 0.2) & (angle > -65) & (angle < -25)
    coherence = np.linalg.norm(normal[z, y, x, :3], axis=1)[on_cloth]
    assert on_cloth.sum() >= 20
    assert coherence.min() > 0.9


def test_a_surface_narrower_than_a_voxel_covers_its_share_of_the_voxels_face(renderer):
    """A voxel's opacity is how much of its face its surfaces cover: a strip 1.5 cm wide lying
    across the box, in a grid of 6.25 cm voxels, covers about a quarter of the face of the
    voxels it crosses, summed across them: its width, 0.23 of a voxel, within 0.05 a row of
    voxels along it (measured 0.25: 4 of the 16 points of each pixel). Counting every fragment
    whole, a row summed to 1 and thin things (railings, chains, a banner's edge) blocked the
    light a voxel thick."""
    scene = engine.load_scene(SCENES / "cornell_box.json")
    scene.root.children = [node for node in scene.root.children if not node.name.endswith("Box")]
    white = next(node.material for node, _ in scene.root.walk() if node.name == "Bottom Plane")
    width = 0.015
    corners = [[0.01, 0.0, -0.8], [0.01, 0.0, 0.8], [0.01 + width, 0.0, 0.8], [0.01 + width, 0.0, -0.8]]
    scene.root.children.append(engine.Node("Strip", mesh=engine.quad_mesh(corners), material=white))
    renderer.render(scene, mode="voxels", grid=32)
    opacity = np.abs(renderer.voxels("normal")[..., 3])
    x, y, z = voxel_index(renderer, [0.01 + width / 2, 0.0, 0.0])
    rows = opacity[:, y - 1:y + 2, x - 1:x + 2]  # the strip's voxels and their neighbours, [z, y, x]
    per_row = rows.sum(axis=(1, 2))
    along = per_row[voxel_index(renderer, [0, 0, -0.7])[2]:voxel_index(renderer, [0, 0, 0.7])[2]]
    assert along == pytest.approx(width / renderer.voxel_layout.voxel_size, abs=0.05)
