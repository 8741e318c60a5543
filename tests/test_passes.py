"""Single passes on small grids made by hand (VoxelGrid.load): what each computes for a voxel
whose inputs are known, checked against the formula it implements."""
import numpy as np
import pytest

from engine.frame.camera import frame_camera
from engine.frame.settings import RenderSettings
from engine.gpu.context import create_headless_context
from engine.gpu.scene_buffers import SceneBuffers
from engine.gpu.shaders import ProgramLibrary
from engine.passes.cull import CullPass
from engine.passes.faces import FaceViewsPass
from engine.passes.gather import GatherPass
from engine.passes.inject import InjectPass
from engine.passes.shadow import ShadowPass
from engine.scene.model import Camera, Light, VoxelRegion
from engine.voxels.grid import VoxelGrid
from engine.voxels.inspection import VoxelInspection

N = 16
REGION = VoxelRegion(np.zeros(3), 1.6)  # 10 cm voxels over [-0.8, 0.8]^3


@pytest.fixture(scope="module")
def gl():
    ctx = create_headless_context()
    with ctx:
        programs = ProgramLibrary(ctx)
        passes = dict(grid=VoxelGrid(ctx, programs), buffers=SceneBuffers(ctx), cull=CullPass(ctx, programs),
                      inject=InjectPass(ctx, programs), faces=FaceViewsPass(ctx, programs),
                      gather=GatherPass(ctx, programs), inspection=VoxelInspection(ctx, programs))
        passes["shadow"] = ShadowPass(ctx, programs, passes["cull"], 64)
        passes["grid"].ensure(N, (REGION,))
        yield passes
        for resource in passes.values():
            resource.release()
    ctx.release()


def empty():
    return np.zeros((N, N, N, 3), np.float32)


def centre(x, y, z):
    """World position of voxel (x, y, z)'s centre."""
    return REGION.center - REGION.size / 2 + (np.array([x, y, z]) + 0.5) * REGION.size / N


def lights(gl, *scene_lights):
    bounds = (REGION.center - 1, REGION.center + 1)
    camera = frame_camera(Camera(position=REGION.center + [0.0, 0.0, 3.0], look_at=REGION.center), (64, 64), bounds)
    return gl["shadow"].render(list(scene_lights), gl["buffers"], bounds, camera)


def every_voxel(gl):
    return gl["gather"].sort_classes(gl["grid"], 1).segment()


def test_a_voxel_lit_by_a_point_light_reflects_albedo_over_pi_times_its_irradiance(gl):
    """One covered voxel, albedo 0.5, facing up, 0.6 m below a point light of 3 W/sr at 60°
    from its normal: L_base = rho / pi * I cos(theta) / d^2. Its neighbours stay zero."""
    grid = gl["grid"]
    albedo, normal = empty(), empty()
    albedo[8, 5, 7], normal[8, 5, 7] = 0.5, (0.0, 1.0, 0.0)
    grid.load(albedo, normal)
    light_position = centre(7, 5, 8) + 0.6 * np.array([np.sin(np.pi / 3), np.cos(np.pi / 3), 0.0])
    maps = lights(gl, Light("point", np.full(3, 3.0), position=light_position, cast_shadows=False))
    base = gl["inspection"].read_level(grid, gl["inject"].run(grid, maps, every_voxel(gl)))
    expected = 0.5 / np.pi * 3.0 * np.cos(np.pi / 3) / 0.6 ** 2
    assert base[8, 5, 7, :3] == pytest.approx(np.full(3, expected), rel=2e-3)
    base[8, 5, 7] = 0.0
    assert not base.any()


def test_a_mip_cell_is_the_mean_of_its_eight_children(gl):
    """Face views of 3 of a 2^3 cell's voxels, all facing +x and lit alike: the level-1 cell
    holds 3/8 of their premultiplied radiance and coverage on its +x face and nothing on the
    others; level 2 (one covered cell of 8) holds 3/64."""
    grid = gl["grid"]
    albedo, normal = empty(), empty()
    for x, y, z in ((4, 4, 4), (4, 5, 4), (4, 5, 5)):
        albedo[z, y, x], normal[z, y, x] = 0.8, (1.0, 0.0, 0.0)
    grid.load(albedo, normal)
    maps = lights(gl, Light("directional", np.full(3, 2.0), direction=np.array([-1.0, 0.0, 0.0]), cast_shadows=False))
    gl["inject"].run(grid, maps, every_voxel(gl))
    gl["faces"].compose(grid, gl["inject"].base, None, every_voxel(gl))
    gl["faces"].mipmap(grid)
    radiance = 0.8 / np.pi * 2.0
    for level, fraction in ((1, 3 / 8), (2, 3 / 64)):
        faces = gl["inspection"].read_faces(grid, gl["faces"].volume, level)
        views = faces.reshape(6, N >> level, N >> level, N >> level, 4)
        cell = 4 >> level
        assert views[0, cell, cell, cell] == pytest.approx([fraction * radiance] * 3 + [fraction], rel=2e-3)
        views[0, cell, cell, cell] = 0.0
        assert not views.any()


def test_a_voxel_facing_a_wide_lit_wall_gathers_the_walls_radiance(gl):
    """A voxel 0.3 m in front of a white wall that fills its view, lit by 3 W/m^2 along its
    normal: all of the lecture's 6 cones stop on the wall, so the gather G = sum_j w_j L is the
    wall's radiance L = rho E / pi (the weights sum to one) within the cones' blur."""
    grid = gl["grid"]
    albedo, normal = empty(), empty()
    albedo[2, :, :], normal[2, :, :] = 1.0, (0.0, 0.0, 1.0)     # the wall at z = 2, facing +z
    albedo[5, 8, 8], normal[5, 8, 8] = 0.5, (0.0, 0.0, -1.0)    # the voxel facing it
    grid.load(albedo, normal)
    maps = lights(gl, Light("directional", np.full(3, 3.0), direction=np.array([0.0, 0.0, -1.0]), cast_shadows=False))
    gl["inject"].run(grid, maps, every_voxel(gl))
    gl["faces"].compose(grid, gl["inject"].base, None, every_voxel(gl))
    gl["faces"].mipmap(grid)
    classes = gl["gather"].sort_classes(grid, 1)
    gl["gather"].hold(grid.records)
    gathered = gl["inspection"].read_level(grid, gl["gather"].run(grid, gl["faces"].cones(grid), RenderSettings(diffuse_cones="six").cone_uniforms(),
                                                gl["gather"].gathered[0], classes.anchor_segment(0), classes.filled_segment(0),
                                                classes.finer_segments(0)))
    assert gathered[5, 8, 8, :3] == pytest.approx(np.full(3, 3.0 / np.pi), rel=0.01)


def test_mips_rebuilt_over_one_interleave_class_equal_mips_rebuilt_everywhere(gl):
    """Two walls meeting at an edge, lit, their face views and mips built; then one interleave
    class relit and composed again, with level 1 rebuilt over that class's cells (and those
    where classes meet) only, as a progressive frame does: every level equals the levels
    rebuilt from level 0 over every cell."""
    grid = gl["grid"]
    albedo, normal = empty(), empty()
    albedo[4, 2:12, 2:12], normal[4, 2:12, 2:12] = 0.7, (0.0, 0.0, 1.0)
    albedo[4:12, 2:12, 2], normal[4:12, 2:12, 2] = 0.6, (1.0, 0.0, 0.0)
    grid.load(albedo, normal)
    classes = gl["gather"].sort_classes(grid, 4)
    for intensity, segment in ((2.0, classes.segment()), (5.0, classes.segment(1))):
        maps = lights(gl, Light("directional", np.full(3, intensity), direction=np.array([-0.5, 0.0, -1.0]), cast_shadows=False))
        gl["inject"].run(grid, maps, segment)
        gl["faces"].compose(grid, gl["inject"].base, None, segment)
        if intensity == 2.0:
            gl["faces"].mipmap(grid)
            before = gl["inspection"].read_faces(grid, gl["faces"].volume, 1)
    gl["faces"].mipmap(grid, [(segment, 1) for segment in classes.cell_segments(1)])
    partial = [gl["inspection"].read_faces(grid, gl["faces"].volume, level) for level in range(1, grid.mip_count)]
    gl["faces"].mipmap(grid)
    full = [gl["inspection"].read_faces(grid, gl["faces"].volume, level) for level in range(1, grid.mip_count)]
    assert not np.array_equal(partial[0], before)
    for level, (a, b) in enumerate(zip(partial, full), start=1):
        assert np.array_equal(a, b), f"level {level} differs"


def test_voxels_between_anchors_take_a_gather_that_varies_linearly_along_the_wall(gl):
    """On a flat wall the gather anchors are the voxels at even coordinates along it, 1 in 4;
    every other voxel takes the tent-weighted mean of the anchors around it, which reproduces
    a gather that varies linearly along the wall, and takes nothing from the anchors of a wall
    at right angles to it, which face another way."""
    grid = gl["grid"]
    albedo, normal = empty(), empty()
    albedo[5, 2:14, 2:14], normal[5, 2:14, 2:14] = 0.5, (0.0, 0.0, 1.0)   # the wall, facing +z
    albedo[6:14, 2:14, 2], normal[6:14, 2:14, 2] = 0.5, (1.0, 0.0, 0.0)   # one along its edge, facing +x
    grid.load(albedo, normal)
    classes = gl["gather"].sort_classes(grid, 1)
    assert classes.anchor_segment(0).read()[1] == 36 + 24  # even along each wall: 6 x 6 and 6 x 4
    z, y, x = np.mgrid[0:N, 0:N, 0:N]
    linear = (0.1 + 0.02 * x + 0.03 * y)[..., None] * np.array([1.0, 0.5, 0.25])
    wall = (z == 5) & (x >= 2) & (y >= 2) & (x < 14) & (y < 14)
    side = (x == 2) & (z >= 6) & (y >= 2) & (y < 14) & (z < 14)
    wall_anchors, side_anchors = wall & (x % 2 == 0) & (y % 2 == 0), side & (y % 2 == 0) & (z % 2 == 0)
    anchors = np.zeros((N, N, N, 4), np.float32)  # the anchors' gathers (a = 1 where traced)
    anchors[wall_anchors] = np.concatenate([linear[wall_anchors], np.ones((wall_anchors.sum(), 1))], axis=-1)
    anchors[side_anchors] = (10.0, 10.0, 10.0, 1.0)
    gl["gather"].hold(grid.records)
    values = gl["gather"].gathered[0]
    grid.write_values(values, anchors)
    filled = gl["inspection"].read_level(grid, gl["gather"].fill(grid, values, classes.filled_segment(0), classes.finer_segments(0)))
    inner = (z == 5) & (x >= 3) & (y >= 3) & (x < 13) & (y < 13)
    assert np.allclose(filled[inner][:, :3], linear[inner], rtol=2e-3)
