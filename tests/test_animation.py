"""glTF animations, evaluated by the scene model in time.

Facts: a node's translation, rotation and scale channels move it as their samplers say
(LINEAR interpolates, rotations along the shorter great arc; STEP holds a keyframe until the
next; CUBICSPLINE passes through its keyframes with the tangents given), holding the first and
last keyframe outside their times; what a node carries (a mesh, a light, a camera) moves with
it; several animations play together, looping over the longest, or one alone by name; a scene
file that loads an animated glTF as a mesh plays it too; skins and morph targets are drawn in
the rest pose with one warning; samplers whose times do not increase, whose outputs do not
match their inputs, or an unknown animation name are one line naming the file and element.
"""
import json
import math

import numpy as np
import pytest

import engine
from engine import SceneError
from engine.core.transforms import rotate_euler_deg
from engine.scene.animation import Sampler
from test_cli import assert_one_line_error, vct  # tests/ is on sys.path under pytest
from test_mesh_files import Gltf

from conftest import SCENES

ROOM = SCENES / "animated_room.glb"


def quaternion_y(degrees):
    half = math.radians(degrees) / 2
    return [0.0, math.sin(half), 0.0, math.cos(half)]


def animated_gltf(path, channels, extra=None):
    """A glTF of one quad node ("Card") and one light node ("Lamp"), with an animation "Move"
    of `channels`: (node name, path, times, values, interpolation)."""
    g = Gltf()
    mesh = g.add("meshes", {"primitives": [g.quad()]})
    card = g.add("nodes", {"name": "Card", "mesh": mesh})
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 683.0}]}}
    lamp = g.add("nodes", {"name": "Lamp", "translation": [0, 0, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}]
    eye = g.add("nodes", {"name": "Eye", "camera": 0, "translation": [0, 0, 3]})
    g.doc["scenes"][0]["nodes"] = [card, lamp, eye]
    nodes = {"Card": card, "Lamp": lamp}
    samplers, targets = [], []
    for name, target, times, values, interpolation in channels:
        samplers.append({"input": g.accessor(np.asarray(times, np.float32)),
                         "output": g.accessor(np.asarray(values, np.float32)), "interpolation": interpolation})
        targets.append({"sampler": len(samplers) - 1, "target": {"node": nodes[name], "path": target}})
    g.doc["animations"] = [{"name": "Move", "samplers": samplers, "channels": targets}]
    if extra:
        extra(g)
    return g.write(path)


def test_linear_translation_is_interpolated_and_held_outside_its_keyframes(tmp_path):
    path = animated_gltf(tmp_path / "a.glb", [("Card", "translation", [1, 3], [[0, 0, 0], [2, 4, 0]], "LINEAR")])
    scene = engine.load_scene(path)
    card = scene.root.find("Card")
    assert scene.animations() == {"Move": 3.0}
    for t, expected in ((0.0, [0, 0, 0]), (1.0, [0, 0, 0]), (2.0, [1, 2, 0]), (2.5, [1.5, 3, 0])):
        scene.pose_at(t)
        assert np.allclose(card.translation, expected), (t, card.translation)
    scene.pose_at(2.999)
    assert np.allclose(card.translation, [2, 4, 0], atol=0.01)


def test_rotation_follows_the_shorter_arc_and_step_holds_a_keyframe(tmp_path):
    # 0 -> 350 degrees about y: the shorter arc goes through -5 degrees, not 175.
    path = animated_gltf(tmp_path / "a.glb", [("Card", "rotation", [0, 1], [quaternion_y(0), quaternion_y(350)], "LINEAR"),
                                              ("Card", "scale", [0, 1, 2], [[1, 1, 1], [2, 2, 2], [3, 3, 3]], "STEP")])
    scene = engine.load_scene(path)
    card = scene.root.find("Card")
    scene.pose_at(0.5)
    forward = rotate_euler_deg(card.rotation_deg)[:3, :3] @ [0, 0, 1]
    assert math.isclose(math.degrees(math.atan2(forward[0], forward[2])), -5.0, abs_tol=1e-3)
    assert np.allclose(card.scale, 1.0)  # STEP: the keyframe at 0 holds until 1
    scene.pose_at(1.5)
    assert np.allclose(card.scale, 2.0)


def test_cubic_spline_passes_through_keyframes_with_the_given_tangents():
    # One coordinate from 0 (tangent 0) to 1 (tangent 3 per second) over 1 s.
    values = np.array([[[0, 0, 0], [0, 0, 0], [0, 0, 0]], [[3, 0, 0], [1, 0, 0], [0, 0, 0]]], float)
    sampler = Sampler(np.array([0.0, 1.0]), values, "CUBICSPLINE", rotation=False)
    assert np.allclose(sampler.at(0.0), 0.0) and np.allclose(sampler.at(1.0), [1, 0, 0])
    u = 0.5  # Hermite: p(u) = (-2u^3 + 3u^2) p1 + (u^3 - u^2) m1
    assert np.isclose(sampler.at(0.5)[0], (-2 * u ** 3 + 3 * u ** 2) + (u ** 3 - u ** 2) * 3.0)
    slope = (sampler.at(1.0)[0] - sampler.at(0.999)[0]) / 0.001
    assert math.isclose(slope, 3.0, rel_tol=0.01)


def test_what_a_node_carries_moves_with_it(tmp_path):
    path = animated_gltf(tmp_path / "a.glb", [("Lamp", "translation", [0, 1], [[0, 0, 2], [0, 1, 2]], "LINEAR"),
                                              ("Card", "translation", [0, 1], [[0, 0, 0], [1, 0, 0]], "LINEAR")])
    scene = engine.load_scene(path)
    rest = np.mean(scene.bounds(), axis=0)
    scene.pose_at(0.5)
    (_, lamp), = scene.lights()
    assert np.allclose(lamp.position, [0, 0.5, 2])
    assert np.allclose(np.mean(scene.bounds(), axis=0) - rest, [0.5, 0, 0])


def test_animations_loop_over_the_longest_and_play_one_by_name():
    scene = engine.load_scene(ROOM)
    assert scene.animations() == {"Play": 4.0, "Dolly": 6.0}
    blue = scene.root.find("Blue")
    scene.pose_at(1.0)
    at_one = blue.translation.copy(), scene.camera.position.copy()
    scene.pose_at(7.0)  # the longest lasts 6 s
    assert np.allclose(blue.translation, at_one[0]) and np.allclose(scene.camera.position, at_one[1])
    scene.pose_at(5.0, "Play")  # Play alone loops over its own 4 s: 5 s is 1 s
    assert np.allclose(blue.translation, at_one[0])
    camera_before = scene.camera.position.copy()
    scene.pose_at(2.0, "Play")
    assert np.allclose(scene.camera.position, camera_before)  # the camera is Dolly's
    with pytest.raises(engine.VctError, match='no animation named "Walk"'):
        scene.pose_at(0.0, "Walk")


def test_a_scene_file_plays_the_animations_of_the_gltf_it_loads(tmp_path):
    animated_gltf(tmp_path / "a.glb", [("Card", "translation", [0, 1], [[0, 0, 0], [1, 0, 0]], "LINEAR")])
    scene_file = tmp_path / "s.json"
    scene_file.write_text(json.dumps({"objects": [{"name": "Card File", "type": "mesh", "file": "a.glb", "translation": [0, 1, 0]}],
                                      "lights": [{"type": "point", "position": [0, 2, 3], "intensity": [1, 1, 1]}],
                                      "camera": {"position": [0, 1, 4], "look_at": [0, 1, 0]}}))
    scene = engine.load_scene(scene_file)
    assert scene.animations() == {"Move": 1.0}
    rest = np.mean(scene.bounds(), axis=0)
    scene.pose_at(0.5)
    assert np.allclose(np.mean(scene.bounds(), axis=0) - rest, [0.5, 0, 0])


@pytest.mark.parametrize("channel, element, message", [
    (("Card", "translation", [0, 1, 1], [[0, 0, 0]] * 3, "LINEAR"), "animations[0].samplers[0].input",
     "strictly increasing"),
    (("Card", "translation", [0, 1], [[0, 0, 0]] * 3, "LINEAR"), "animations[0].samplers[0].output",
     "has 3 elements; LINEAR over 2 input times needs 2"),
    (("Card", "translation", [0, 1], [[0, 0, 0]] * 2, "CUBICSPLINE"), "animations[0].samplers[0].output", "needs 6"),
    (("Card", "rotation", [0, 1], [[0, 0, 0, 0]] * 2, "LINEAR"), "animations[0].samplers[0].output", "unit quaternions"),
    (("Card", "translation", [0, 1], [[0, 0, 0]] * 2, "BEZIER"), "animations[0].samplers[0].interpolation", "BEZIER"),
])
def test_malformed_samplers_are_one_line_naming_the_element(tmp_path, channel, element, message):
    path = animated_gltf(tmp_path / "a.glb", [channel])
    with pytest.raises(SceneError) as caught:
        engine.load_scene(path)
    assert element in str(caught.value) and message in str(caught.value), str(caught.value)
    assert_one_line_error(vct("render", path, "--out", tmp_path / "x.png"), "a.glb", element)


def test_an_unknown_animation_is_one_line_naming_it(tmp_path):
    result = vct("render", ROOM, "--animation", "Walk", "--out", tmp_path / "x.png")
    assert_one_line_error(result, "--animation", '"Walk"', '"Play", "Dolly"')
    assert not list(tmp_path.iterdir())


def test_readme_animation_loop_renders_the_scene_moving(tmp_path, monkeypatch):
    """The README's loop over an animated glTF, at 48x48, grid 16, 3 frames 1 s apart: each
    frame lit, and the animation moves what they show."""
    from PIL import Image
    from test_scene_api import readme_example

    code = readme_example("What `vct render --frames` does is this loop", [
        ("engine.Renderer(256, 256)", "engine.Renderer(48, 48, engine.RenderSettings(grid=16))"),
        ("range(120)", "range(3)"), ("i / 30.0", "float(i)"), ('"scenes/animated_room.glb"', repr(str(ROOM)))])
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md: animation loop", "exec"), {})
    frames = [np.asarray(Image.open(tmp_path / f"room_{i:04d}.png"), float) for i in range(3)]
    assert min(frame.mean() for frame in frames) > 10
    assert np.abs(frames[1] - frames[0]).mean() > 1.0 and np.abs(frames[2] - frames[1]).mean() > 1.0
