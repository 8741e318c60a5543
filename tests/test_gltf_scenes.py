"""glTF/GLB files as whole scenes: cameras, KHR_lights_punctual, KHR_texture_transform,
COLOR_0 and TEXCOORD_1, as authored.

Facts: `vct render FILE.glb` renders the file with its own camera (the first, or --camera
NAME; perspective or orthographic; an image 640 wide at the camera's aspect ratio unless
--width/--height say otherwise) and its lights (point and spot intensities in candela become
W/sr at 683 lm/W, directional lux W/m^2, with colour, range and cone angles); a texture
transform scales, turns and moves the texture coordinates as the extension defines; COLOR_0
multiplies the base colour; textures read TEXCOORD_1 where they say so; a file without a
camera is seen from one framing its bounds, with one warning line; extensions the file uses
that vct does not read get one warning line naming them; a scene file that loads a glTF as a
mesh takes its lights unless it lists its own, and its camera unless it has one; malformed
cameras and lights, and --camera naming no camera, are one line naming the file and the
element.
"""
import json
import math
from pathlib import Path

import numpy as np
import pytest

import engine
from engine import SceneError, VctWarning, load_scene
from test_cli import assert_one_line_error, vct  # tests/ is on sys.path under pytest
from test_mesh_files import Gltf, png

ROOT = Path(__file__).resolve().parent.parent
ROOM = ROOT / "scenes" / "references" / "gltf_room.glb"
FLOOR = np.array([[-1, 0, 1], [1, 0, 1], [1, 0, -1], [-1, 0, -1]], np.float32)  # facing +y
CARD = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)   # facing +z
CARD_UV = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)                 # image top-left at (-1, 1)


def face(g, corners, material=None, texcoords=CARD_UV, colors=None, texcoords1=None):
    """A mesh of one quad."""
    attributes = {"POSITION": g.accessor(corners), "NORMAL": g.accessor(np.tile(np.cross(corners[1] - corners[0],
                                                                                        corners[2] - corners[0]), (4, 1)) / 4.0)}
    if texcoords is not None:
        attributes["TEXCOORD_0"] = g.accessor(texcoords)
    if colors is not None:
        attributes["COLOR_0"] = g.accessor(np.asarray(colors, np.float32))
    if texcoords1 is not None:
        attributes["TEXCOORD_1"] = g.accessor(np.asarray(texcoords1, np.float32))
    primitive = {"attributes": attributes, "indices": g.accessor(np.array([0, 1, 2, 0, 2, 3], np.uint32), 5125)}
    if material is not None:
        primitive["material"] = material
    return g.add("meshes", {"primitives": [primitive]})


def node(g, spec):
    index = g.add("nodes", spec)
    g.doc["scenes"][0]["nodes"].append(index)
    return index


def camera_node(g, spec, translation=(0, 0, 3), rotation=(0, 0, 0, 1), name="Camera"):
    g.doc.setdefault("cameras", []).append(spec)
    return node(g, {"name": name, "camera": len(g.doc["cameras"]) - 1, "translation": list(translation),
                    "rotation": list(rotation)})


PERSPECTIVE = {"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 2.0, "znear": 0.1}}


def lights(g, *specs):
    g.doc.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": list(specs)}
    g.doc.setdefault("extensionsUsed", []).append("KHR_lights_punctual")


def light_node(g, index, translation, rotation=(0, 0, 0, 1), name=None):
    return node(g, {"name": name or f"Light {index}", "translation": list(translation), "rotation": list(rotation),
                    "extensions": {"KHR_lights_punctual": {"light": index}}})


DOWN = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))  # -z turned to -y: a light or camera looking down


def lit_floor(tmp_path, light, translation=(0, 1, 0), rotation=DOWN, albedo=0.5):
    """A white floor 2 m wide seen from 3 m above by a camera looking down, lit by one light."""
    g = Gltf()
    white = g.add("materials", {"pbrMetallicRoughness": {"baseColorFactor": [albedo] * 3 + [1], "metallicFactor": 0.0}})
    node(g, {"name": "Floor", "mesh": face(g, FLOOR, white, texcoords=None)})
    camera_node(g, {"type": "perspective", "perspective": {"yfov": 0.3, "aspectRatio": 1.0, "znear": 0.1}}, (0, 3, 0), DOWN)
    lights(g, light)
    light_node(g, 0, translation, rotation)
    return g.write(tmp_path / "floor.glb")


@pytest.fixture(scope="module")
def small():
    with engine.Renderer(16, 16) as r:
        yield r


def test_the_room_renders_from_its_own_camera_lit_by_its_own_lights(tmp_path):
    """The reference room as it comes from its generator: camera "Camera", two KHR lights, lit."""
    scene = load_scene(ROOM)
    assert scene.camera.name == "Camera" and (scene.camera.width, scene.camera.height) == (640, 640)
    np.testing.assert_allclose(scene.camera.position, [0, 1.4, 1.9])
    assert sorted(node.name for node, _ in scene.lights()) == ["Ceiling Lamp", "Spot"]
    result = vct("render", ROOM, "--out", tmp_path / "room.png", "--hdr", tmp_path / "room.npy", "--width", "32",
                 "--height", "32", "--grid", "16")
    assert result.returncode == 0 and result.stderr == "", result.stderr
    image = np.load(tmp_path / "room.npy")
    assert image.shape == (32, 32, 3) and image.mean() > 0.05 and np.all(np.isfinite(image))


def test_bench_times_a_gltf_file_as_the_scene(tmp_path):
    """`vct bench room.glb`: the file's own camera, lights and objects in the frame kinds."""
    result = vct("bench", ROOM, "--grids", "16", "--frames", "1", "--warmup", "0", "--width", "32", "--height", "32",
                 "--json", tmp_path / "bench.json")
    assert result.returncode == 0, result.stderr
    moves = {r["frame"]: r["moves"] for r in json.loads((tmp_path / "bench.json").read_text())}
    meshes = {node.name for node, _ in load_scene(ROOM).drawables()}
    assert moves["static"] == "camera" and moves["light"] == "Ceiling Lamp" and moves["object"] in meshes


def test_a_perspective_camera_looks_along_its_nodes_minus_z_with_the_files_field_of_view(tmp_path):
    g = Gltf()
    node(g, {"mesh": face(g, CARD, texcoords=None)})
    camera_node(g, PERSPECTIVE, (0, 0, 3))
    camera = load_scene(g.write(tmp_path / "c.glb")).camera
    np.testing.assert_allclose(camera.look_at - camera.position, [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(camera.up, [0, 1, 0], atol=1e-12)
    assert camera.vertical_fov_deg == pytest.approx(math.degrees(0.8))
    assert (camera.width, camera.height, camera.projection) == (640, 320, "perspective")


def test_an_orthographic_camera_sees_ymag_metres_above_and_below_its_axis(small, tmp_path):
    """ymag 2 over a card 2 m high: the card fills the middle half of the rows."""
    g = Gltf()
    node(g, {"mesh": face(g, CARD, texcoords=None)})
    camera_node(g, {"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 2.0, "znear": 0.1, "zfar": 10}}, (0, 0, 3))
    scene = load_scene(g.write(tmp_path / "o.glb"))
    scene.root.children.append(engine.scene.model.Node(name="Sun", light=engine.scene.model.Light(
        "directional", np.ones(3), direction=np.array([0.0, 0.0, -1.0]))))
    assert scene.camera.projection == "orthographic" and scene.camera.half_height == 2.0
    covered = small.render(scene, mode="albedo").max(axis=2) > 0
    assert covered[4:12, 4:12].all() and not covered[:3].any() and not covered[13:].any()


@pytest.mark.parametrize("light, expected", [
    ({"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 683.0}, [1.0, 0.5, 0.25]),
    ({"type": "directional", "intensity": 683.0 * 2}, [2.0, 2.0, 2.0]),
    ({"type": "spot", "intensity": 683.0, "spot": {"innerConeAngle": 0.9, "outerConeAngle": 1.2}}, [1.0, 1.0, 1.0]),
], ids=["point", "directional", "spot"])
def test_punctual_lights_light_a_floor_as_their_photometric_intensity_says(small, tmp_path, light, expected):
    """683 cd at 1 m straight above (683 lux for the directional light) is 1 W/m^2: a floor of
    albedo 0.5 returns 0.5 / pi of it under the light."""
    scene = load_scene(lit_floor(tmp_path, light))
    (_, world_light), = scene.lights()
    np.testing.assert_allclose(world_light.intensity, expected)
    np.testing.assert_allclose(world_light.direction, [0, -1, 0], atol=1e-9)
    centre = small.render(scene, mode="direct")[7:9, 7:9].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(centre, 0.5 / math.pi * np.array(expected), rtol=0.03)


def test_a_lights_range_and_spot_cone_come_from_the_file(tmp_path):
    light = {"type": "spot", "range": 5.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}
    (_, world_light), = load_scene(lit_floor(tmp_path, light)).lights()
    assert world_light.range == 5.0
    assert (world_light.inner_angle_deg, world_light.outer_angle_deg) == pytest.approx((math.degrees(0.2), math.degrees(0.6)))


def textured_card(tmp_path, info, image, texcoords1=None, colors=None):
    """A card facing a camera that sees it whole, its base colour the PNG `image` through the
    textureInfo `info` (its index filled in)."""
    g = Gltf()
    texture = g.texture(g.image(png(image)))
    material = g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": dict(info, index=texture),
                                                            "metallicFactor": 0.0}})
    node(g, {"mesh": face(g, CARD, material, colors=colors, texcoords1=texcoords1)})
    camera_node(g, {"type": "orthographic", "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.1}}, (0, 0, 3))
    return load_scene(g.write(tmp_path / "t.glb"))


HALVES = np.array([[[255, 0, 0], [0, 0, 255]]], np.uint8)  # left red, right blue


def columns(image):
    """The colour of each column of the image's middle row: 'r', 'b' or '.'."""
    row = image[image.shape[0] // 2]
    return "".join("r" if p[0] > p[2] else "b" if p[2] > p[0] else "." for p in row)


@pytest.mark.parametrize("transform, expected", [
    ({}, "rrrrrrrrbbbbbbbb"),
    ({"scale": [2.0, 1.0]}, "rrrrbbbbrrrrbbbb"),
    ({"offset": [0.5, 0.0]}, "bbbbbbbbrrrrrrrr"),
    ({"rotation": math.pi, "offset": [1.0, 1.0]}, "bbbbbbbbrrrrrrrr"),
], ids=["none", "scale", "offset", "rotation"])
def test_a_texture_transform_scales_turns_and_moves_the_coordinates(small, tmp_path, transform, expected):
    """KHR_texture_transform: u' = R S u + offset, R = [[cos, sin], [-sin, cos]]; turned by pi
    and moved by (1, 1), the image shows mirrored in both axes."""
    info = {"extensions": {"KHR_texture_transform": transform}} if transform else {}
    scene = textured_card(tmp_path, info, HALVES)
    assert columns(small.render(scene, mode="albedo")) == expected


def test_a_texture_may_read_the_second_texture_coordinate_set(small, tmp_path):
    """TEXCOORD_1 mirrored in u: the texture shows mirrored."""
    mirrored = np.array([[1, 1], [0, 1], [0, 0], [1, 0]], np.float32)
    scene = textured_card(tmp_path, {"texCoord": 1}, HALVES, texcoords1=mirrored)
    assert columns(small.render(scene, mode="albedo")) == "bbbbbbbbrrrrrrrr"
    scene = textured_card(tmp_path, {"texCoord": 1, "extensions": {"KHR_texture_transform": {"texCoord": 0}}}, HALVES,
                          texcoords1=mirrored)
    assert columns(small.render(scene, mode="albedo")) == "rrrrrrrrbbbbbbbb"


def test_vertex_colours_multiply_the_base_colour(small, tmp_path):
    white = np.full((1, 1, 3), 255, np.uint8)
    colors = [[0, 1, 0], [0, 1, 0], [1, 0, 0], [1, 0, 0]]  # green at the bottom corners, red at the top
    image = small.render(textured_card(tmp_path, {}, white, colors=colors), mode="albedo")
    assert image[1, 8, 0] > 0.8 and image[1, 8, 1] < 0.2   # near the top: red
    assert image[14, 8, 1] > 0.8 and image[14, 8, 0] < 0.2  # near the bottom: green


def test_a_file_without_a_camera_is_seen_framed_and_unread_extensions_are_named_once(tmp_path):
    """A model file is framed as model viewers frame it, without a word; the extensions it
    uses that vct does not read are named in one line."""
    g = Gltf()
    node(g, {"mesh": face(g, CARD, texcoords=None)})
    g.doc["extensionsUsed"] = ["KHR_materials_clearcoat", "KHR_texture_transform", "EXT_meshopt_compression"]
    with pytest.warns(VctWarning) as record:
        scene = load_scene(g.write(tmp_path / "bare.glb"))
    messages = [str(w.message) for w in record]
    assert len(messages) == 1
    assert "uses extensions vct does not read, drawn without them: EXT_meshopt_compression, KHR_materials_clearcoat" in messages[0]
    np.testing.assert_allclose(scene.camera.look_at, [0, 0, 0], atol=1e-12)


def scene_with_mesh(tmp_path, **extra):
    g = Gltf()
    node(g, {"name": "Card", "mesh": face(g, CARD, texcoords=None)})
    camera_node(g, PERSPECTIVE, (0, 0, 4), name="File Camera")
    lights(g, {"type": "point", "intensity": 683.0})
    light_node(g, 0, (0, 0, 2), name="File Lamp")
    g.write(tmp_path / "part.glb")
    document = {"objects": [{"name": "Part", "type": "mesh", "file": "part.glb"}], **extra}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(document))
    return load_scene(path)


def test_a_scene_file_takes_the_lights_and_camera_of_its_gltf_unless_it_has_its_own(tmp_path):
    scene = scene_with_mesh(tmp_path)
    assert [node.name for node, _ in scene.lights()] == ["File Lamp"] and scene.camera.name == "File Camera"
    own = scene_with_mesh(tmp_path, camera={"position": [0, 0, 5], "look_at": [0, 0, 0]},
                          lights=[{"name": "Own", "type": "point", "position": [0, 1, 1], "intensity": [1, 1, 1]}])
    assert [node.name for node, _ in own.lights()] == ["Own"] and own.camera.name == "camera"


def test_camera_picks_a_camera_node_by_name_and_a_missing_one_is_one_line(tmp_path):
    scene = scene_with_mesh(tmp_path, camera={"position": [0, 0, 5], "look_at": [0, 0, 0]})
    assert load_scene(tmp_path / "scene.json", camera="File Camera").camera.name == "File Camera"
    assert scene.camera.name == "camera"
    result = vct("render", tmp_path / "scene.json", "--out", tmp_path / "x.png", "--camera", "Nope")
    assert_one_line_error(result, 'camera: no camera node named "Nope" (the scene has: "File Camera")')


def _spot(inner, outer):
    return {"type": "spot", "spot": {"innerConeAngle": inner, "outerConeAngle": outer}}


BAD = {
    "negative intensity": ({"type": "point", "intensity": -1.0}, None, "lights[0].intensity", "at least 0"),
    "unknown light type": ({"type": "area"}, None, "lights[0].type", '"area"'),
    "inner cone beyond outer": (_spot(0.6, 0.4), None, "lights[0].spot.innerConeAngle", "less than outerConeAngle"),
    "spot wider than its shadow": (_spot(0.2, 1.57), None, "lights[0].spot.outerConeAngle", "at most"),
    "zero field of view": (None, {"type": "perspective", "perspective": {"yfov": 0.0, "znear": 0.1}}, "cameras[0].perspective.yfov",
                           "positive"),
    "unknown camera type": (None, {"type": "fisheye"}, "cameras[0].type", '"fisheye"'),
}


@pytest.mark.parametrize("case", BAD)
def test_a_malformed_light_or_camera_is_one_line_naming_the_file_and_the_element(tmp_path, case):
    light, camera, field, problem = BAD[case]
    g = Gltf()
    node(g, {"mesh": face(g, CARD, texcoords=None)})
    if light is not None:
        lights(g, light)
        light_node(g, 0, (0, 1, 0))
    if camera is not None:
        camera_node(g, camera)
    path = g.write(tmp_path / "bad.glb")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and field in message and problem in message, message
    assert_one_line_error(vct("render", path, "--out", tmp_path / "x.png"), field)
