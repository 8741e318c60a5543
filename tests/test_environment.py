"""The environment: light from beyond the scene (a uniform sky or an equirectangular map).

Facts: the camera sees the map where no surface is, in Mitsuba's envmap convention (the map's
left edge looking along -z, a quarter across along +x, rotation_y_deg turning it about +y),
as the reference tool's Mitsuba scene does; a floor under a uniform sky alone receives
E = pi L (direct light, and the same in gi with nothing to bounce); the viewer's sky light,
spread over frames, ends as one frame's; glTF's layers under a
uniform sky (a white furnace) return the light that arrives, dielectrics and metals at every
roughness, where layers simply added would return more; a mirror shows the sky; bad maps and
bad --environment values exit 2 with one line; a scene nothing can light renders with one
warning line, and so does one whose lights reach nothing the camera sees.
"""
import importlib.util
import json
import math
import struct
from pathlib import Path

import numpy as np
import pytest

import engine
from engine import SceneError, load_scene
from engine.core.constants import SKY_FILTER_RADIUS, SKY_NEAR_REACH
from test_cli import assert_one_line_error, vct  # tests/ is on sys.path under pytest

ROOT = Path(__file__).resolve().parent.parent
CARD = [[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]]
# Four bands of the map, centred on the directions -z, +x, +z, -x (u = 0, 1/4, 1/2, 3/4).
BANDS = {"-z": [1.0, 0.0, 0.0], "+x": [0.0, 1.0, 0.0], "+z": [0.0, 0.0, 1.0], "-x": [1.0, 1.0, 1.0]}
LOOK = {"-z": [0, 0, -1], "+x": [1, 0, 0], "+z": [0, 0, 1], "-x": [-1, 0, 0]}


def band_map(width=64, height=32):
    u = (np.arange(width) + 0.5) / width
    band = np.floor((u + 1 / 8) * 4).astype(int) % 4
    colours = np.array(list(BANDS.values()), np.float32)
    return np.ascontiguousarray(np.broadcast_to(colours[band][None], (height, width, 3)))


def write(directory, document, name="scene.json"):
    path = Path(directory) / name
    path.write_text(json.dumps(document))
    return path


def sky_scene(directory, objects=(), environment=None, look="-z", size=16, materials=None):
    """The camera at the origin looking along `look`, a small card far below (so the scene has a
    surface), and the environment."""
    objects = list(objects) or [{"name": "Card", "type": "quad", "material": "m", "translation": [0, -50, 0],
                                 "rotation": [-90, 0, 0], "vertices": CARD}]
    return write(directory, {
        "camera": {"position": [0, 0, 0], "look_at": LOOK[look], "vertical_fov_deg": 5, "width": size, "height": size},
        "materials": materials or {"m": {"albedo": [0.5, 0.5, 0.5]}},
        "objects": objects, "environment": environment or {"radiance": [1, 1, 1]}})


@pytest.fixture(scope="module")
def small():
    with engine.Renderer(16, 16) as r:
        yield r


@pytest.mark.parametrize("look, rotation, seen", [("-z", 0, "-z"), ("+x", 0, "+x"), ("+z", 0, "+z"), ("-x", 0, "-x"),
                                                  ("+x", 90, "+z"), ("-z", 90, "+x")])
def test_the_camera_sees_the_map_where_no_surface_is_in_mitsubas_envmap_convention(small, tmp_path, look, rotation, seen):
    """Turned by 90 degrees about +y, the map shows at +x what it shows at +z unturned."""
    engine.save_exr(tmp_path / "bands.exr", band_map())
    scene = load_scene(sky_scene(tmp_path, environment={"map": "bands.exr", "rotation_y_deg": rotation}, look=look))
    image = small.render(scene, mode="gi", grid=16)
    np.testing.assert_allclose(image[6:10, 6:10].reshape(-1, 3).mean(axis=0), BANDS[seen], atol=0.02)


def test_the_reference_tool_reads_the_map_the_same_way(tmp_path):
    mitsuba = pytest.importorskip("mitsuba")
    spec = importlib.util.spec_from_file_location("reference_tool", ROOT / "tools" / "reference.py")
    reference = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(reference)
    reference.use_mitsuba("scalar_rgb")
    engine.save_exr(tmp_path / "bands.exr", band_map())
    for look, rotation, seen in (("+x", 0, "+x"), ("+x", 90, "+z")):
        scene = load_scene(sky_scene(tmp_path, environment={"map": "bands.exr", "rotation_y_deg": rotation}, look=look, size=8))
        image, _, _, _ = reference.render(scene, spp=8, max_depth=2, pass_spp=4)
        np.testing.assert_allclose(image[3:5, 3:5].reshape(-1, 3).mean(axis=0), BANDS[seen], atol=0.02)
    assert mitsuba is not None


def floor_under_sky(directory, albedo=0.5):
    floor = {"name": "Floor", "type": "quad", "material": "m", "vertices": [[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]]}
    return write(directory, {"camera": {"position": [0, 1, 0.01], "look_at": [0, 0, 0], "vertical_fov_deg": 10,
                                        "width": 16, "height": 16},
                             "materials": {"m": {"albedo": [albedo] * 3}}, "objects": [floor],
                             "environment": {"radiance": [2, 2, 2]}})


@pytest.mark.parametrize("mode", ["direct", "gi"])
def test_a_floor_under_a_uniform_sky_alone_receives_pi_times_its_radiance(small, tmp_path, mode):
    """L = rho / pi E = rho L_sky: 0.5 x 2 = 1; nothing else to bounce from, so gi is the same."""
    image = small.render(load_scene(floor_under_sky(tmp_path)), mode=mode, grid=32)
    assert image[4:12, 4:12].mean() == pytest.approx(1.0, rel=0.01)


def test_a_sky_taken_away_and_given_back_lights_the_scene_as_before(tmp_path):
    """The sky's light at the voxels is held only while the scene has a sky: after a frame
    without one, the same sky lights the floor again as it did before."""
    scene = load_scene(write(tmp_path, {
        "camera": {"position": [0, 2, 0.01], "look_at": [0, 0, 0], "width": 16, "height": 16},
        "materials": {"white": {"albedo": [0.5, 0.5, 0.5]}},
        "objects": [{"type": "quad", "material": "white", "vertices": [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]]}],
        "environment": {"radiance": [1.0, 0.8, 0.6]}}))
    with engine.Renderer(16, 16) as r:
        first = r.render(scene, grid=32)
        sky, scene.environment = scene.environment, None
        dark = r.render(scene, grid=32)
        scene.environment = sky
        again = r.render(scene, grid=32)
    assert first[6:10, 6:10, 0].mean() == pytest.approx(0.5, rel=0.05) and dark.max() == 0.0
    assert np.array_equal(first, again)


def test_the_viewers_sky_light_spread_over_frames_ends_as_one_frames(small):
    """Progressive frames trace the sky's cones at one interleave class's anchors a frame, and
    every voxel interpolates the anchors traced so far: once every class is traced the voxels
    hold the light a headless frame computes at once, to the bit."""
    scene = load_scene(Path(__file__).parents[1] / "scenes" / "references" / "open_box_sky.json")
    with engine.Renderer(64, 64) as viewer:
        viewer.progressive = True
        for _ in range(2 * viewer.settings.bounce_interleave):
            viewer.render(scene, grid=32)
        spread = viewer.voxels("radiance")
    small.render(scene, grid=32)
    assert np.array_equal(spread, small.voxels("radiance"))


def test_while_an_object_moves_under_a_sky_only_the_voxels_near_it_are_relit_the_rest_once_it_rests(tmp_path):
    """A 0.5 m plate slides 3.5 m above a floor under a sky: in the viewer each step relights the
    sky's light within SKY_NEAR_REACH times its size of it (an occluder hides at most 1/72 of
    the sky beyond), so the floor below it, further away than that and the sky filter's reach,
    keeps the light it had to the bit, though the plate's shadow on the sky moved; once the
    plate rests, a round over the classes gives every voxel the light a new renderer's has."""
    floor = {"name": "Floor", "type": "quad", "material": "m", "vertices": [[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]]}
    plate = {"name": "Plate", "type": "box", "material": "m", "center": [0.0, 3.5, 0.0], "size": [0.5, 0.02, 0.5]}
    path = tmp_path / "plate_over_floor.json"
    path.write_text(json.dumps({
        "camera": {"position": [0, 1, 3], "look_at": [0, 0, 0], "width": 32, "height": 32},
        "materials": {"m": {"albedo": [0.5, 0.5, 0.5]}}, "objects": [floor, plate], "environment": {"radiance": [1, 1, 1]}}))
    scene = load_scene(path)
    rest = 2 * engine.RenderSettings().bounce_interleave
    with engine.Renderer(32, 32) as viewer:
        viewer.progressive = True
        for _ in range(rest):
            viewer.render(scene, grid=32)
        before = viewer.voxels("radiance")
        for _ in range(rest):  # 0.2 m, a step a frame
            scene.root.find("Plate").translation += [0.2 / rest, 0.0, 0.0]
            viewer.render(scene, grid=32)
        moving = viewer.voxels("radiance")
        lo, hi = viewer.voxel_layout.level_bounds(0)
        voxel = (hi - lo)[0] / 32
        centres = lo + (np.indices((32, 32, 32)).transpose(1, 2, 3, 0)[..., ::-1] + 0.5) * voxel  # [z, y, x] -> (x, y, z)
        reach = SKY_NEAR_REACH * 0.7 + (SKY_FILTER_RADIUS + 2) * voxel  # past the plates' box: the relit box's, the filter's
        below = (centres[..., 1] < 3.5 - 0.01 - reach) & (np.abs(centres[..., 0] - 0.1) < 0.35) & (np.abs(centres[..., 2]) < 0.25)
        below &= before[..., 3] > 0
        assert below.sum() >= 8 and np.array_equal(moving[below], before[below])
        for _ in range(rest):
            viewer.render(scene, grid=32)
        with engine.Renderer(32, 32) as fresh:
            fresh.progressive = True
            for _ in range(rest):
                fresh.render(scene, grid=32)
            expected = fresh.voxels("radiance")
        assert not np.array_equal(expected[below], before[below])  # where the plate's shadow on the sky moved
        assert np.array_equal(viewer.voxels("radiance"), expected)


# What the card returns seen at n.v = 1/2: the diffuse layer's 1 - F(1/2) = 0.93 of the sky's 1
# plus the specular lobe's directional albedo A there, by Monte Carlo over cosine-weighted light
# directions (2M samples; independent of engine/core/specular_lobe.py's table): 0.070, 0.068 and 0.031
# for the dielectric at roughness 0.1, 0.5 and 1 (Smith's masking takes more of a rough lobe's
# light), 0.996 and 0.517 for metals of F0 1 and 0.5 at roughness 0.3.
@pytest.mark.parametrize("material, returned", [
    ({"albedo": [1, 1, 1], "specular": 0.04, "roughness": 0.1}, 0.93 + 0.070),
    ({"albedo": [1, 1, 1], "specular": 0.04, "roughness": 0.5}, 0.93 + 0.068),
    ({"albedo": [1, 1, 1], "specular": 0.04, "roughness": 1.0}, 0.93 + 0.031),
    ({"albedo": [1, 1, 1], "metalness": 1.0, "roughness": 0.3}, 0.996),
    ({"albedo": [0.5, 0.5, 0.5], "metalness": 1.0, "roughness": 0.3}, 0.517),
], ids=["dielectric-0.1", "dielectric-0.5", "dielectric-1", "white-metal", "grey-metal"])
def test_a_white_furnace_of_gltf_layers_returns_at_most_what_arrives(small, tmp_path, material, returned):
    """A card under a uniform sky of 1, seen at 60 degrees from its normal (n.v = 1/2): a white
    dielectric returns 1 - F(n.v) of the light from its diffuse layer and its specular lobe's
    directional albedo A from the other (1 for a smooth lobe; added, the layers would return
    1 + F = 1.07), a metal A of its base colour as F0."""
    eye = [1.5 * math.sin(math.radians(60)), 0, 1.5 * math.cos(math.radians(60))]
    scene = load_scene(write(tmp_path, {
        "camera": {"position": eye, "look_at": [0, 0, 0], "vertical_fov_deg": 20, "width": 16, "height": 16},
        "materials": {"s": material}, "environment": {"radiance": [1, 1, 1]},
        "objects": [{"name": "Card", "type": "quad", "material": "s", "vertices": CARD}]}))
    centre = small.render(scene, grid=32)[6:10, 6:10]
    assert centre.max() <= 1.005
    assert centre.mean() == pytest.approx(returned, rel=0.015)


def test_a_mirror_shows_the_sky(small, tmp_path):
    """A smooth metal floor seen at 45 degrees reflects the map's band in the mirrored direction:
    looking down along -z, it shows what lies up along -z, red."""
    engine.save_exr(tmp_path / "bands.exr", band_map())
    mirror = {"name": "Mirror", "type": "quad", "material": "chrome", "vertices": [[-5, 0, 5], [5, 0, 5], [5, 0, -5], [-5, 0, -5]]}
    scene = load_scene(write(tmp_path, {
        "camera": {"position": [0, 1, 0], "look_at": [0, 0, -1], "vertical_fov_deg": 5, "width": 16, "height": 16},
        "materials": {"chrome": {"albedo": [1, 1, 1], "metalness": 1.0, "roughness": 0.0}},
        "objects": [mirror], "environment": {"map": "bands.exr"}}))
    np.testing.assert_allclose(small.render(scene, grid=32)[6:10, 6:10].reshape(-1, 3).mean(axis=0), BANDS["-z"], atol=0.05)


def test_a_closed_rooms_converged_brightness_follows_the_layered_albedo(small, tmp_path):
    """A closed box of walls that emit 1 and reflect as a glTF dielectric of base colour 0.6 and
    roughness 1: its voxels pass on rho = 0.6 (1 - E) + A_h, E = 0.04 + 0.96 / 21 the mean of
    F and A_h = 0.0269 the specular lobe's hemispherical albedo (Monte Carlo, as above), so the
    room settles at L = 1 / (1 - rho); a wall seen head-on returns 1 + (0.96 0.6 + A(1)) L,
    A(1) = 0.0152. Layers simply added (rho = 0.6 + E) would make it 3.04, the lobe's masking
    neglected (A = F) 2.68, instead of 2.39."""
    h = 2.0
    walls = {"Floor": [[-h, -h, -h], [-h, -h, h], [h, -h, h], [h, -h, -h]], "Ceiling": [[-h, h, -h], [h, h, -h], [h, h, h], [-h, h, h]],
             "Left": [[-h, -h, -h], [-h, h, -h], [-h, h, h], [-h, -h, h]], "Right": [[h, -h, -h], [h, -h, h], [h, h, h], [h, h, -h]],
             "Back": [[-h, -h, -h], [h, -h, -h], [h, h, -h], [-h, h, -h]], "Front": [[-h, -h, h], [-h, h, h], [h, h, h], [h, -h, h]]}
    scene = load_scene(write(tmp_path, {
        "camera": {"position": [0, 0, 1.5], "look_at": [0, 0, 0], "vertical_fov_deg": 30, "width": 16, "height": 16},
        "materials": {"wall": {"albedo": [0.6] * 3, "emission": [1, 1, 1], "specular": 0.04, "roughness": 1.0}},
        "objects": [{"name": name, "type": "quad", "material": "wall", "vertices": v} for name, v in walls.items()]}))
    e = 0.04 + 0.96 / 21
    settled = 1.0 / (1.0 - (0.6 * (1 - e) + 0.0269))
    seen = 1.0 + (0.96 * 0.6 + 0.0152) * settled
    assert small.render(scene, grid=64)[6:10, 6:10].mean() == pytest.approx(seen, rel=0.02)


def header_only_exr(width, height):
    """The header of a float RGB OpenEXR of width x height and no pixels."""
    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value
    channels = b"".join(c.encode() + b"\0" + struct.pack("<iBBBBii", 2, 0, 0, 0, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (attribute("channels", "chlist", channels) + attribute("compression", "compression", b"\0")
              + attribute("dataWindow", "box2i", box) + attribute("displayWindow", "box2i", box)
              + attribute("lineOrder", "lineOrder", b"\0") + attribute("pixelAspectRatio", "float", struct.pack("<f", 1))
              + attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
              + attribute("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    return struct.pack("<ii", 20000630, 2) + header + bytes(8 * height)


def _map(pixels):
    def make(directory):
        engine.save_exr(Path(directory) / "sky.exr", np.asarray(pixels, np.float32))
        return "sky.exr"
    return make


def _bytes(name, data):
    def make(directory):
        (Path(directory) / name).write_bytes(data)
        return name
    return make


BAD_MAPS = {
    "missing": (lambda directory: "nothing.exr", "file not found"),
    "corrupt": (_bytes("sky.exr", b"not an OpenEXR file"), "cannot decode OpenEXR"),
    "not floating point": (_bytes("sky.png", b"\x89PNG"), "linear radiance: .exr or .hdr, not .png"),
    "negative texel": (_map([[[1, 1, 1], [1, -0.5, 1]]]), "texel (row 0, column 1) is [1.0, -0.5, 1.0]"),
    "NaN texel": (_map([[[1, 1, 1], [np.nan, 1, 1]]]), "must be finite and not negative"),
    "too many pixels": (_bytes("sky.exr", header_only_exr(20000, 4)), "20000x4 pixels: at most 16384 on a side"),
}


@pytest.mark.parametrize("case", BAD_MAPS)
def test_a_bad_environment_map_is_one_line_naming_the_file_and_the_field(tmp_path, case):
    make, problem = BAD_MAPS[case]
    name = make(tmp_path)
    path = sky_scene(tmp_path, environment={"map": name})
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value).startswith(f'{path}: environment.map: "{name}": ') and problem in str(info.value), str(info.value)


def test_a_map_wider_than_the_drivers_textures_is_an_error_naming_it(small, tmp_path):
    """The driver's GL_MAX_TEXTURE_SIZE (here made 64) bounds the map: a VctError naming the
    scene file and the map, before anything is drawn."""
    engine.save_exr(tmp_path / "wide.exr", np.ones((64, 128, 3), np.float32))
    scene = load_scene(sky_scene(tmp_path, environment={"map": "wide.exr"}))
    limit = small.ctx.info["GL_MAX_TEXTURE_SIZE"]
    small.ctx.info["GL_MAX_TEXTURE_SIZE"] = 64
    try:
        with pytest.raises(engine.VctError, match=r'environment.map "wide.exr".*128x64 exceeds the driver.s texture limit of 64'):
            small.render(scene, grid=16)
    finally:
        small.ctx.info["GL_MAX_TEXTURE_SIZE"] = limit


def test_an_environment_is_a_sky_or_a_map_not_both(tmp_path):
    with pytest.raises(SceneError, match='environment: give "radiance"'):
        load_scene(sky_scene(tmp_path, environment={"radiance": [1, 1, 1], "map": "sky.exr"}))


def test_environment_from_the_command_line_replaces_the_scenes(tmp_path):
    """--environment R,G,B: a uniform sky; --environment FILE: a map; a bad one exits 2."""
    scene = sky_scene(tmp_path, environment={"radiance": [1, 1, 1]})
    out = tmp_path / "x.npy"
    assert vct("render", scene, "--out", tmp_path / "x.png", "--hdr", out, "--environment", "0,0.5,0", "--grid", "16").returncode == 0
    np.testing.assert_allclose(np.load(out)[6:10, 6:10].reshape(-1, 3).mean(axis=0), [0, 0.5, 0], atol=0.01)
    engine.save_exr(tmp_path / "bands.exr", band_map())
    assert vct("render", scene, "--out", tmp_path / "x.png", "--hdr", out, "--environment", tmp_path / "bands.exr",
               "--grid", "16").returncode == 0
    np.testing.assert_allclose(np.load(out)[6:10, 6:10].reshape(-1, 3).mean(axis=0), BANDS["-z"], atol=0.02)
    assert_one_line_error(vct("render", scene, "--out", tmp_path / "y.png", "--environment", "1,-1,1"), "--environment")
    assert_one_line_error(vct("render", scene, "--out", tmp_path / "y.png", "--environment", tmp_path / "none.exr"),
                          "--environment", "file not found")


def test_a_scene_nothing_can_light_is_shown_under_the_studio_sky_or_black_with_one_warning_line(tmp_path):
    """No light, no emitter, no environment: the commands light it with the studio sky (one
    line says so); `--environment none` keeps it black, and one line says why."""
    document = json.loads((ROOT / "scenes" / "cornell_box.json").read_text())
    document["lights"] = []
    path = write(tmp_path, document)
    result = vct("render", path, "--out", tmp_path / "x.png", "--hdr", tmp_path / "x.npy", "--width", "16", "--height", "16",
                 "--grid", "16")
    assert result.returncode == 0 and len(result.stderr.splitlines()) == 1
    assert result.stderr.startswith(f"vct: warning: {path}: no light in the scene: shown under the studio sky")
    assert np.load(tmp_path / "x.npy").mean() > 0.001  # the box is open at the front only
    result = vct("render", path, "--out", tmp_path / "x.png", "--hdr", tmp_path / "x.npy", "--width", "16", "--height", "16",
                 "--grid", "16", "--environment", "none")
    assert result.returncode == 0 and len(result.stderr.splitlines()) == 1
    assert result.stderr.startswith(f"vct: warning: {path}: no light: the scene has no lights, no emissive surfaces "
                                    "and no environment")
    assert np.load(tmp_path / "x.npy").max() == 0.0


def test_a_light_enclosed_by_geometry_renders_with_one_warning_line_naming_it(tmp_path):
    """The Cornell box's light inside a small closed box: the camera sees only its outside."""
    document = json.loads((ROOT / "scenes" / "cornell_box.json").read_text())
    document["objects"] = [{"name": "Lantern", "type": "box", "material": "white", "center": [0, 0.7, 0], "size": [0.3, 0.3, 0.3]}]
    document["camera"]["position"] = [0, 0.7, 3]
    document["camera"]["look_at"] = [0, 0.7, 0]
    path = write(tmp_path, document)
    result = vct("render", path, "--out", tmp_path / "x.png", "--width", "16", "--height", "16", "--grid", "16")
    assert result.returncode == 0, result.stderr
    assert result.stderr.startswith('vct: warning: ') and '"Omni Light" reaches nothing the camera sees' in result.stderr
    assert len(result.stderr.splitlines()) == 1
