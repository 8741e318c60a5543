"""Scene files (engine.formats.scene_file.load_scene): what a JSON scene loads into, and how bad input fails.

Loading facts: the reference Cornell box loads unchanged into a "Cornell Box" node; quads face
where the right-hand rule of their vertex order says; boxes, spheres, groups and mesh files
(tests/data: OBJ, PLY, GLB, found relative to the scene file) land where their transforms put
them. Bad-input facts: every malformed scene raises SceneError with one line that names the file
and the field. BAD_SCENES is shared with tests/test_cli.py, which feeds the same files to `vct`.
"""
import json
import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import jsonschema
import numpy as np
import pytest

from conftest import REFERENCE, REQUIRE_REFERENCES, reference_file  # tests/ is on sys.path under pytest
from engine import SceneError, VctWarning, load_scene
from engine.core.transforms import transform_points
from engine.formats.scene_schema import SCHEMA, default, reference_text, schema_text

ROOT = Path(__file__).resolve().parent.parent
CORNELL = ROOT / "scenes" / "cornell_box.json"
REFERENCE_CORNELL = REFERENCE / "cornell_box.json"
DATA = Path(__file__).resolve().parent / "data"

CORNELL_NAMES = ["Left Plane", "Right Plane", "Bottom Plane", "Top Plane", "Near Plane", "Far Plane",
                 "Short Box", "Tall Box", "Omni Light"]


def cornell_data():
    return json.loads(CORNELL.read_text())


def write_scene(directory, content, name="scene.json"):
    """Write a scene (a dict, JSON text or raw bytes) to directory/name, with the test meshes
    copied to directory/meshes/ so that `"file": "meshes/..."` resolves relative to the scene."""
    directory = Path(directory)
    shutil.copytree(DATA, directory / "meshes", dirs_exist_ok=True)
    path = directory / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content if isinstance(content, str) else json.dumps(content, indent=1))
    return path


def small_scene(objects=(), lights=(), materials=None):
    """A scene with the Cornell camera, one white material and the given objects and lights."""
    return {"camera": cornell_data()["camera"],
            "materials": materials or {"white": {"albedo": [0.73, 0.73, 0.73]}},
            "objects": list(objects), "lights": list(lights)}


def world_bounds(scene, name):
    for node, world in scene.drawables():
        if node.name == name:
            return node.mesh.bounds(world)
    raise AssertionError(f"no drawable named {name!r}")


def ry(deg):
    """Right-handed rotation about +y: +x turns towards -z for a positive angle."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


# ---- the Cornell box -------------------------------------------------------------------------

def test_scenes_cornell_box_is_the_reference_file_unchanged():
    assert CORNELL.read_bytes() == reference_file(REFERENCE_CORNELL).read_bytes()


def test_cornell_box_loads_objects_and_light_as_children_of_a_cornell_box_node_in_file_order():
    scene = load_scene(CORNELL)
    assert scene.root.name == "Cornell Box"
    assert [child.name for child in scene.root.children] == CORNELL_NAMES
    *objects, light = scene.root.children
    assert all(node.mesh is not None and node.material is not None and node.light is None for node in objects)
    assert light.light is not None and light.mesh is None
    assert [node.name for node, _ in scene.drawables()] == CORNELL_NAMES[:8]


def test_cornell_box_materials_have_the_file_albedos_and_are_lambertian():
    scene = load_scene(CORNELL)
    albedo = {node.name: node.material.albedo for node in scene.root.children if node.material}
    np.testing.assert_array_equal(albedo["Left Plane"], [0.65, 0.05, 0.05])  # red
    np.testing.assert_array_equal(albedo["Right Plane"], [0.12, 0.45, 0.15])  # green
    for name in ("Bottom Plane", "Top Plane", "Near Plane", "Far Plane", "Short Box", "Tall Box"):
        np.testing.assert_array_equal(albedo[name], [0.73, 0.73, 0.73])  # white
    assert sorted(scene.materials) == ["green", "red", "white"]
    for material in scene.materials.values():
        assert material.metalness == 0.0 and material.specular == 0.0
        np.testing.assert_array_equal(material.emission, [0.0, 0.0, 0.0])


def test_a_material_is_single_sided_unless_the_file_says_double_sided():
    """Quads are one-sided (their back faces culled) as the spec says; `double_sided` makes a thin
    sheet whose both sides reflect (scenes/references/thin_panel.json)."""
    assert not any(m.double_sided for m in load_scene(CORNELL).materials.values())
    thin = load_scene(CORNELL.parent / "references" / "thin_panel.json").materials
    assert thin["thin white"].double_sided and not thin["white"].double_sided


def test_cornell_box_camera_has_the_file_fields():
    camera = load_scene(CORNELL).camera
    np.testing.assert_array_equal(camera.position, [0.0, 0.0, 0.95])
    np.testing.assert_array_equal(camera.look_at, [0.0, 0.0, -1.0])
    np.testing.assert_array_equal(camera.up, [0.0, 1.0, 0.0])
    assert camera.vertical_fov_deg == 60.0
    assert (camera.width, camera.height) == (256, 256)


def test_cornell_box_point_light_is_3_w_per_sr_at_0_07_0_with_no_range_cut_off():
    (node, light), = load_scene(CORNELL).lights()
    assert node.name == "Omni Light"
    assert light.type == "point"
    np.testing.assert_array_equal(light.intensity, [3.0, 3.0, 3.0])
    np.testing.assert_allclose(light.position, [0.0, 0.7, 0.0])
    assert light.range == 0.0
    assert light.cast_shadows


@pytest.mark.parametrize("name, inward", [
    ("Left Plane", [1, 0, 0]), ("Right Plane", [-1, 0, 0]), ("Bottom Plane", [0, 1, 0]),
    ("Top Plane", [0, -1, 0]), ("Near Plane", [0, 0, -1]), ("Far Plane", [0, 0, 1]),
])
def test_quad_normal_follows_the_right_hand_rule_of_its_vertex_order(name, inward):
    node, world = next((n, m) for n, m in load_scene(CORNELL).drawables() if n.name == name)
    p = transform_points(world, node.mesh.positions)
    geometric = np.cross(p[1] - p[0], p[2] - p[0])
    np.testing.assert_allclose(geometric / np.linalg.norm(geometric), inward, atol=1e-12)
    shading = node.mesh.normals @ np.linalg.inv(world[:3, :3])  # n' = (M^-1)^T n
    np.testing.assert_allclose(shading / np.linalg.norm(shading, axis=1, keepdims=True), np.tile(inward, (4, 1)), atol=1e-12)
    for a, b, c in node.mesh.indices:  # both triangles wind the same way
        n = np.cross(p[b] - p[a], p[c] - p[a])
        assert np.dot(n, inward) > 0


# ---- boxes, spheres, groups ------------------------------------------------------------------

def test_box_center_size_and_rotation_y_deg_give_the_expected_world_corners():
    scene = load_scene(CORNELL)
    node, world = next((n, m) for n, m in scene.drawables() if n.name == "Short Box")
    corners = np.array([[x, y, z] for x in (-0.3, 0.3) for y in (-0.3, 0.3) for z in (-0.3, 0.3)])
    expected = corners @ ry(-18.0).T + [0.4, -0.7, 0.15]
    got = transform_points(world, node.mesh.positions)
    assert {tuple(np.round(c, 9)) for c in got} == {tuple(np.round(c, 9)) for c in expected}
    half = 0.3 * (math.cos(math.radians(18)) + math.sin(math.radians(18)))
    lo, hi = world_bounds(scene, "Short Box")
    np.testing.assert_allclose(lo, [0.4 - half, -1.0, 0.15 - half], atol=1e-12)
    np.testing.assert_allclose(hi, [0.4 + half, -0.4, 0.15 + half], atol=1e-12)


def test_cornell_boxes_rest_on_the_floor():
    scene = load_scene(CORNELL)
    assert world_bounds(scene, "Short Box")[0][1] == pytest.approx(-1.0)
    assert world_bounds(scene, "Tall Box")[0][1] == pytest.approx(-1.0)
    assert world_bounds(scene, "Tall Box")[1][1] == pytest.approx(0.2)


@pytest.mark.parametrize("rotation", [{"rotation_y_deg": 90.0}, {"rotation": [0.0, 90.0, 0.0]}])
def test_rotation_about_y_is_right_handed_so_plus_x_turns_towards_minus_z(tmp_path, rotation):
    box = {"name": "B", "type": "box", "material": "white", "center": [0, 0, 0], "size": [1, 1, 1], **rotation}
    node, world = load_scene(write_scene(tmp_path, small_scene([box]))).drawables()[0]
    np.testing.assert_allclose(transform_points(world, [[0.5, 0.0, 0.0]])[0], [0.0, 0.0, -0.5], atol=1e-12)
    np.testing.assert_allclose(transform_points(world, [[0.0, 0.0, 0.5]])[0], [0.5, 0.0, 0.0], atol=1e-12)


def test_sphere_center_and_radius_give_its_bounds(tmp_path):
    sphere = {"name": "Ball", "type": "sphere", "material": "white", "center": [0.5, 0.25, -1.0], "radius": 0.25}
    lo, hi = world_bounds(load_scene(write_scene(tmp_path, small_scene([sphere]))), "Ball")
    np.testing.assert_allclose(lo, [0.25, 0.0, -1.25], atol=1e-12)
    np.testing.assert_allclose(hi, [0.75, 0.5, -0.75], atol=1e-12)


def test_group_children_compose_translation_rotation_and_scale_of_their_parents(tmp_path):
    group = {"name": "Outer", "type": "group", "translation": [1, 2, 3], "rotation": [0, 90, 0], "scale": [2, 2, 2],
             "children": [
                 {"name": "Ball", "type": "sphere", "material": "white", "center": [1, 0, 0], "radius": 0.5},
                 {"name": "Inner", "type": "group", "translation": [0, 1, 0],
                  "children": [{"name": "Cube", "type": "box", "material": "white", "center": [0, 0, 0], "size": [1, 1, 1]}]},
             ]}
    scene = load_scene(write_scene(tmp_path, small_scene([group])))
    outer = scene.root.find("Outer")
    assert [c.name for c in outer.children] == ["Ball", "Inner"] and outer.mesh is None
    assert scene.root.find("Inner").children[0].name == "Cube"
    # Ball: (1,2,3) + Ry(90) * 2 * (1,0,0) = (1,2,1), radius 2 * 0.5.
    lo, hi = world_bounds(scene, "Ball")
    np.testing.assert_allclose((lo + hi) / 2, [1, 2, 1], atol=1e-9)
    np.testing.assert_allclose(hi - lo, [2, 2, 2], atol=1e-9)
    # Cube: (1,2,3) + Ry(90) * 2 * (0,1,0) = (1,4,3), side 2.
    lo, hi = world_bounds(scene, "Cube")
    np.testing.assert_allclose(lo, [0, 3, 2], atol=1e-9)
    np.testing.assert_allclose(hi, [2, 5, 4], atol=1e-9)


def test_lights_nested_in_a_transformed_group_move_and_turn_with_it(tmp_path):
    group = {"name": "Rig", "type": "group", "translation": [0, 1, 0], "rotation": [0, 0, 90], "children": [
        {"name": "Bulb", "type": "point", "position": [0, 0.5, 0], "intensity": [1, 1, 1]},
        {"name": "Spot", "type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0], "intensity": [1, 1, 1]},
    ]}
    scene = load_scene(write_scene(tmp_path, small_scene([group])))
    lights = {node.name: light for node, light in scene.lights()}
    # Rz(90) turns +y into -x and -y into +x.
    np.testing.assert_allclose(lights["Bulb"].position, [-0.5, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(lights["Spot"].position, [0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(lights["Spot"].direction, [1.0, 0.0, 0.0], atol=1e-12)
    # The node keeps its local position: the world position is derived, not written back.
    np.testing.assert_array_equal(scene.root.find("Bulb").light.position, [0, 0.5, 0])


# ---- mesh files ------------------------------------------------------------------------------

@pytest.mark.parametrize("file, transform, lo, hi", [
    ("tetrahedron.obj", {}, [0, 0, 0], [1, 2, 3]),
    ("tetrahedron.obj", {"translation": [1, 0, 0], "scale": [2, 2, 2]}, [1, 0, 0], [3, 4, 6]),
    ("pyramid.ply", {}, [-1, -0.5, -1], [1, 0.5, 1]),
    ("box.glb", {}, [0, 0, 0], [2, 4, 6]),
], ids=["obj", "obj-translated-scaled", "ply", "glb"])
def test_mesh_file_relative_to_the_scene_file_loads_with_the_right_bounds(tmp_path, monkeypatch, file, transform, lo, hi):
    path = write_scene(tmp_path / "scenes", small_scene([{"name": "M", "type": "mesh", "material": "white",
                                                          "file": f"meshes/{file}", **transform}]))
    monkeypatch.chdir(tmp_path)  # the file is found next to the scene, not in the working directory
    scene = load_scene(path)
    got_lo, got_hi = world_bounds(scene, "M")
    np.testing.assert_allclose(got_lo, lo, atol=1e-6)
    np.testing.assert_allclose(got_hi, hi, atol=1e-6)
    node = scene.root.find("M")
    assert node.mesh.indices.shape[1] == 3 and len(node.mesh.indices) > 0
    assert node.mesh.normals.shape == node.mesh.positions.shape


def test_objects_of_one_mesh_file_each_land_where_their_own_transform_puts_them(tmp_path):
    objects = [{"name": f"T{i}", "type": "mesh", "material": "white", "file": "meshes/tetrahedron.obj",
                "translation": [10 * i, 0, 0]} for i in range(2)]
    scene = load_scene(write_scene(tmp_path, small_scene(objects)))
    np.testing.assert_allclose(world_bounds(scene, "T0")[0], [0, 0, 0])
    np.testing.assert_allclose(world_bounds(scene, "T1")[0], [10, 0, 0])


def test_mesh_arrays_are_read_only_so_an_edit_replaces_an_array():
    """Every mesh's arrays refuse in-place writes (the renderer spots geometry edits by array
    identity); an array assigned later is made read-only too."""
    scene = load_scene(CORNELL)
    for node, _ in scene.drawables():
        for array in (node.mesh.positions, node.mesh.normals, node.mesh.indices):
            assert not array.flags.writeable, node.name
    mesh = scene.root.find("Left Plane").mesh
    with pytest.raises(ValueError):
        mesh.positions[0] = [0.0, 0.0, 0.0]
    mesh.positions = mesh.positions + 1.0
    assert not mesh.positions.flags.writeable


# ---- bad input -------------------------------------------------------------------------------

@dataclass
class BadScene:
    """A broken scene: `make()` returns its content (dict, JSON text or bytes); the error must
    name `field` (None: there is no field, e.g. the file is not text) and mention `mention`."""

    id: str
    make: Callable
    field: str = None
    mention: str = ""


def _edit(change):
    def make():
        data = cornell_data()
        change(data)
        return data
    return make


def _text(old, new):
    def make():
        text = CORNELL.read_text()
        assert old in text
        return text.replace(old, new, 1)
    return make


def _set(path, value):
    """Set data[path[0]][path[1]]... = value."""
    def change(data):
        target = data
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return _edit(change)


def _add_object(spec):
    return _edit(lambda data: data["objects"].append(spec))


def _nested_groups(levels):
    """Groups nested `levels` deep around one box."""
    node = {"name": "Deepest", "type": "box", "material": "white", "size": [0.1, 0.1, 0.1]}
    for level in range(levels):
        node = {"name": f"Level {level}", "type": "group", "children": [node]}
    return node


def _malformed_line():
    return 1 + next(i for i, line in enumerate(CORNELL.read_text().splitlines()) if '"width"' in line)


SHORT_BOX = 'objects[6] "Short Box"'
LEFT_PLANE = 'objects[0] "Left Plane"'

BAD_SCENES = [
    BadScene("malformed-json", _text('"width": 256,', '"width": 256,,'), f"line {_malformed_line()} column", "malformed JSON"),
    BadScene("not-an-object", lambda: "[1, 2, 3]", None, "must be a JSON object"),
    BadScene("not-utf8", lambda: b'{"camera": "\xff"}', None, "UTF-8"),
    BadScene("unknown-material", _set(["objects", 0, "material"], "gold"), f"{LEFT_PLANE}.material", "gold"),
    BadScene("unknown-object-type", _set(["objects", 6, "type"], "cylinder"), f"{SHORT_BOX}.type", "cylinder"),
    BadScene("unknown-light-type", _set(["lights", 0, "type"], "area"), 'lights[0] "Omni Light".type', '"area"'),
    BadScene("missing-mesh-file", _add_object({"name": "Bunny", "type": "mesh", "material": "white",
                                               "file": "meshes/bunny.obj"}), 'objects[8] "Bunny".file', "bunny.obj"),
    BadScene("mesh-file-name-with-a-nul", _add_object({"name": "Nul", "type": "mesh", "material": "white",
                                                      "file": "meshes/\u0000.obj"}), 'objects[8] "Nul".file', "cannot read"),
    BadScene("mesh-file-name-too-long", _add_object({"name": "Long", "type": "mesh", "material": "white",
                                                    "file": "x" * 300}), 'objects[8] "Long".file', "too long"),
    BadScene("unreadable-mesh-file", _add_object({"name": "Broken", "type": "mesh", "material": "white",
                                                  "file": "meshes/broken.ply"}), 'objects[8] "Broken".file', "broken.ply"),
    BadScene("mesh-file-without-triangles", _add_object({"name": "Text", "type": "mesh", "material": "white",
                                                         "file": "meshes/not_a_mesh.obj"}), 'objects[8] "Text".file', "not_a_mesh.obj"),
    BadScene("collinear-quad", _set(["objects", 0, "vertices"], [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]),
             f"{LEFT_PLANE}.vertices", "degenerate"),
    BadScene("zero-area-quad", _set(["objects", 0, "vertices"], [[0.5, 0.5, 0.5]] * 4), f"{LEFT_PLANE}.vertices", "degenerate"),
    BadScene("quad-with-three-vertices", _set(["objects", 0, "vertices"], [[0, 0, 0], [1, 0, 0], [0, 1, 0]]),
             f"{LEFT_PLANE}.vertices", "4 vertices"),
    BadScene("zero-box-size", _set(["objects", 6, "size"], [0.0, 0.6, 0.6]), f"{SHORT_BOX}.size[0]", "positive"),
    BadScene("negative-box-size", _set(["objects", 6, "size"], [0.6, -0.6, 0.6]), f"{SHORT_BOX}.size[1]", "positive"),
    BadScene("zero-sphere-radius", _add_object({"name": "Ball", "type": "sphere", "material": "white", "radius": 0}),
             'objects[8] "Ball".radius', "positive"),
    BadScene("zero-scale", _set(["objects", 7, "scale"], [1, 1, 0]), 'objects[7] "Tall Box".scale[2]', "positive"),
    BadScene("nan-literal", _text('"position": [0.0, 0.7, 0.0]', '"position": [0.0, NaN, 0.0]'), "lights[0].position[1]", "NaN"),
    BadScene("infinity-literal", _text('"vertical_fov_deg": 60.0', '"vertical_fov_deg": -Infinity'),
             "camera.vertical_fov_deg", "Infinity"),
    BadScene("nan-string", _set(["objects", 0, "vertices", 1], [-1, "NaN", -1]), f"{LEFT_PLANE}.vertices[1][1]", "number"),
    BadScene("integer-too-large-for-a-float", _set(["camera", "position"], [0, 0, 10 ** 400]), "camera.position[2]", "at most"),
    BadScene("vector-of-two", _set(["camera", "position"], [0.0, 0.0]), "camera.position", "3 numbers"),
    BadScene("vertex-of-four", _set(["objects", 0, "vertices", 2], [-1, 1, 1, 1]), f"{LEFT_PLANE}.vertices[2]", "3 numbers"),
    BadScene("albedo-above-one", _set(["materials", "red", "albedo"], [1.2, 0.05, 0.05]), "materials.red.albedo", "at most 1"),
    BadScene("double-sided-not-a-boolean", _set(["materials", "red", "double_sided"], "yes"), "materials.red.double_sided", "must be"),
    BadScene("negative-albedo", _set(["materials", "red", "albedo"], [0.65, -0.05, 0.05]), "materials.red.albedo[1]", "negative"),
    BadScene("fractional-image-width", _set(["camera", "width"], 0.5), "camera.width", "whole number"),
    BadScene("negative-light-intensity", _set(["lights", 0, "intensity"], [3, -3, 3]), 'lights[0] "Omni Light".intensity[1]', "negative"),
    # Values that would not give finite float32 radiance, or transforms that are not invertible.
    BadScene("emission-1e308", _set(["materials", "white", "emission"], [1e308, 0, 0]), "materials.white.emission[0]", "at most"),
    BadScene("emission-beyond-half-floats", _set(["materials", "white", "emission"], [0, 70000, 0]),
             "materials.white.emission[1]", "at most 65504"),
    BadScene("light-intensity-1e308", _set(["lights", 0, "intensity"], [1e308, 3, 3]), 'lights[0] "Omni Light".intensity[0]', "at most"),
    BadScene("translation-1e308", _set(["objects", 6, "translation"], [1e308, 0, 0]), f"{SHORT_BOX}.translation[0]", "at most"),
    BadScene("group-places-its-child-beyond-the-limit",
             _add_object({"name": "Far", "type": "group", "translation": [9e5, 0, 0], "children": [
                 {"name": "Farther", "type": "box", "material": "white", "translation": [9e5, 0, 0], "size": [1, 1, 1]}]}),
             'objects[8] "Far".children[0] "Farther"', "beyond"),
    BadScene("scale-underflowing-to-a-singular-transform",
             _edit(lambda data: data["objects"][7].update(scale=[1e-200, 1, 1], size=[1e-200, 1.2, 0.6])),
             'objects[7] "Tall Box".scale', "world transform"),
    BadScene("nested-scales-compounding-below-the-limit",
             _add_object({"name": "Small", "type": "group", "scale": [1e-4, 1e-4, 1e-4], "children": [
                 {"name": "Smaller", "type": "sphere", "material": "white", "radius": 1e-4}]}),
             'objects[8] "Small".children[0] "Smaller".scale', "world transform"),
    BadScene("voxel-region-of-1e-300", _edit(lambda data: data.update(voxel_region={"center": [0, 0, 0], "size": 1e-300})),
             "voxel_region.size", "at least"),
    BadScene("field-of-view-of-1e-300", _set(["camera", "vertical_fov_deg"], 1e-300), "camera.vertical_fov_deg", "at least"),
    BadScene("children-nested-too-deeply", _add_object(_nested_groups(40)), 'objects[8] "Level 39"', "nest more than"),
    # Unknown or misspelled keys: named with their object, and the nearest valid key.
    BadScene("misspelled-material-field", _set(["materials", "red", "albeod"], [1, 0, 0]), "materials.red",
             'unknown field "albeod" (did you mean "albedo"?)'),
    BadScene("misspelled-roughness", _set(["materials", "red", "roughnes"], 0.5), "materials.red",
             'unknown field "roughnes" (did you mean "roughness"?)'),
    BadScene("misspelled-node-field", _set(["objects", 6, "translaton"], [0, 0, 0]), SHORT_BOX,
             'unknown field "translaton" (did you mean "translation"?)'),
    BadScene("camera-fov", _set(["camera", "fov"], 40), "camera", 'unknown field "fov" (did you mean "vertical_fov_deg"?)'),
    BadScene("a-field-of-another-node-type", _set(["objects", 6, "radius"], 0.3), SHORT_BOX, 'unknown field "radius"'),
    BadScene("misspelled-top-level-key", _set(["objecs"], []), None, 'unknown field "objecs" (did you mean "objects"?)'),
    BadScene("spot-inner-angle-beyond-outer", _set(["lights", 0], {"type": "spot", "position": [0, 0.7, 0], "direction": [0, -1, 0],
                                                                  "intensity": [1, 1, 1], "outer_angle_deg": 30,
                                                                  "inner_angle_deg": 40}), "lights[0].inner_angle_deg",
             "at most outer_angle_deg (30)"),
]


def write_bad_scene(directory, case):
    return write_scene(directory, case.make(), name=f"{case.id}.json")


def assert_names_file_and_field(message, path, case):
    assert "\n" not in message, message
    assert str(path) in message, message
    if case.field:
        assert case.field in message, message
    assert case.mention in message, message


@pytest.mark.parametrize("case", BAD_SCENES, ids=lambda case: case.id)
def test_bad_scene_raises_scene_error_naming_the_file_and_the_field(tmp_path, case):
    path = write_bad_scene(tmp_path, case)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert info.value.source == str(path)
    assert_names_file_and_field(str(info.value), path, case)


def test_malformed_json_error_gives_the_line_and_column_of_the_fault(tmp_path):
    path = write_scene(tmp_path, '{\n  "camera": {\n    "position": [0, 0, 1],,\n  }\n}\n')  # 2nd comma: line 3, column 27
    with pytest.raises(SceneError, match=r"line 3 column 27: malformed JSON"):
        load_scene(path)


def test_missing_scene_file_raises_scene_error_naming_it(tmp_path):
    path = tmp_path / "nowhere.json"
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(path) in str(info.value) and "cannot read" in str(info.value)


def test_python_json_nan_is_rejected_even_where_no_number_is_read(tmp_path):
    """Python's json accepts NaN; JSON does not, so the loader refuses it anywhere in the file."""
    path = write_scene(tmp_path, CORNELL.read_text().replace('"name": "cornell_box"', '"name": "cornell_box", "note": [NaN]'))
    with pytest.raises(SceneError, match=r"note\[0\]: .*NaN"):
        load_scene(path)


def test_the_unedited_base_of_the_bad_input_table_loads(tmp_path):
    """Guards BAD_SCENES: each case fails because of its one edit, not because of the helpers."""
    scene = load_scene(write_scene(tmp_path, cornell_data()))
    assert scene.root.name == "Cornell Box" and len(scene.root.children) == 9


SCENE_FILES = sorted(p for p in [*ROOT.glob("scenes/**/*.json"), *ROOT.glob("tests/scenes/*.json"), REFERENCE_CORNELL]
                     if not p.name.endswith((".meta.json", ".schema.json")))


@pytest.mark.parametrize("path", SCENE_FILES, ids=lambda p: str(p.relative_to(ROOT.parent)))
def test_every_scene_of_the_repository_is_valid_by_the_published_schema(path):
    """As an editor checks it: jsonschema alone, with scenes/scene.schema.json."""
    if not path.exists():
        reference_file(path)
    schema = json.loads((ROOT / "scenes" / "scene.schema.json").read_text())
    jsonschema.Draft202012Validator(schema).validate(json.loads(path.read_text()))


def test_a_scene_without_a_camera_is_seen_from_one_framing_its_bounds_with_one_warning(tmp_path):
    """The bounding sphere of the Cornell box (corners at +-1) fills the 45-degree view."""
    data = cornell_data()
    del data["camera"]
    with pytest.warns(VctWarning, match="no camera: rendering from one that frames the scene's bounds") as record:
        scene = load_scene(write_scene(tmp_path, data))
    assert len(record) == 1
    camera = scene.camera
    np.testing.assert_allclose(camera.look_at, [0, 0, 0], atol=1e-9)
    distance = np.linalg.norm(camera.position - camera.look_at)
    assert distance * math.sin(math.radians(camera.vertical_fov_deg / 2)) == pytest.approx(math.sqrt(3))
    assert (camera.width, camera.height) == (640, 480)


def test_the_published_schema_is_the_one_the_loader_checks():
    assert (ROOT / "scenes" / "scene.schema.json").read_text() == schema_text()


def test_the_format_reference_is_generated_from_the_schema_and_names_every_field():
    reference = (ROOT / "docs" / "SCENE_FORMAT.md").read_text()
    assert reference == reference_text()
    for definition in ("camera", "material", "environment", "voxel_region", "clipmap"):
        for field in SCHEMA["$defs"][definition]["properties"]:
            assert f"| `{field}`" in reference, (definition, field)
    assert "| `roughness` | number | 0..1 | `1.0` |" in reference


def test_the_schema_holds_the_defaults_the_loader_uses(tmp_path):
    """A material and a node with no optional field get the schema's defaults."""
    scene = load_scene(write_scene(tmp_path, small_scene([{"name": "Q", "type": "box", "material": "m", "size": [1, 1, 1]}],
                                                         materials={"m": {}})))
    material, node = scene.materials["m"], scene.root.find("Q")
    assert material.albedo.tolist() == default("material", "albedo") == [0.8, 0.8, 0.8]
    assert (material.roughness, material.metalness, material.specular) == (1.0, 0.0, 0.0)
    assert node.translation.tolist() == [0.0, 0.0, 0.0] and node.scale.tolist() == [1.0, 1.0, 1.0]


@pytest.mark.parametrize("device", ["/dev/zero", "fifo"])
def test_scene_path_that_is_not_a_regular_file_is_refused_without_reading_it(tmp_path, device):
    """/dev/zero would be read until memory runs out, a pipe would block: neither is read."""
    if device == "fifo":
        device = tmp_path / "scene.json"
        os.mkfifo(device)
    with pytest.raises(SceneError, match="not a regular file") as info:
        load_scene(device)
    assert str(device) in str(info.value)


def test_scene_file_larger_than_the_limit_is_refused(tmp_path):
    from engine.formats.scene_file import MAX_SCENE_BYTES

    path = tmp_path / "huge.json"
    with open(path, "wb") as f:
        f.truncate(MAX_SCENE_BYTES + 1)  # sparse: nothing is written to disk
    with pytest.raises(SceneError, match="larger than"):
        load_scene(path)


def test_nan_nested_as_deep_as_json_allows_is_named_without_a_recursion_error(tmp_path):
    depth = 900
    path = write_scene(tmp_path, CORNELL.read_text().replace('"name": "cornell_box"',
                                                             '"name": "cornell_box", "note": ' + "[" * depth + "NaN" + "]" * depth))
    with pytest.raises(SceneError, match=r"note(\[0\]){900}: .*NaN"):
        load_scene(path)


# ---- hostile mesh files ----------------------------------------------------------------------

def mesh_scene(directory, file):
    return write_scene(directory, small_scene([{"name": "M", "type": "mesh", "material": "white", "file": file}]))


@pytest.mark.parametrize("suffix", ["obj", "ply", "glb", "stl"])
def test_noise_as_a_mesh_file_is_one_line_naming_the_field(tmp_path, suffix):
    """Random bytes: an error naming the file and field, not an import error of a text decoder."""
    (tmp_path / f"noise.{suffix}").write_bytes(np.random.default_rng(11).integers(0, 256, 20000, np.uint8).tobytes())
    path = mesh_scene(tmp_path, f"noise.{suffix}")
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert message.startswith(f'{path}: objects[0] "M".file: ') and f"noise.{suffix}" in message, message
    assert "\n" not in message and "module" not in message, message


def test_obj_materials_are_ignored_so_a_section_per_material_still_loads_as_one_mesh(tmp_path):
    """trimesh makes one mesh per `usemtl` section and names them in quadratic time; the scene's
    material applies anyway, so those lines are dropped and 2000 sections load like one."""
    sections = 2000
    lines = ["mtllib nowhere.mtl"]
    for i in range(sections):
        lines += [f"usemtl m{i}", f"v {i} 0 0", f"v {i} 1 0", f"v {i} 0 1", f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}"]
    (tmp_path / "sections.obj").write_text("\n".join(lines) + "\n")
    mesh = load_scene(mesh_scene(tmp_path, "sections.obj")).root.find("M").mesh
    assert len(mesh.indices) == sections


def test_a_mesh_file_used_by_several_objects_is_loaded_once(tmp_path):
    objects = [{"name": f"T{i}", "type": "mesh", "material": "white", "file": "meshes/tetrahedron.obj"} for i in range(3)]
    scene = load_scene(write_scene(tmp_path, small_scene(objects)))
    assert scene.root.find("T0").mesh is scene.root.find("T1").mesh is scene.root.find("T2").mesh


def test_mesh_faces_facing_apart_on_shared_vertices_get_flat_unit_normals(tmp_path):
    """A two-sided triangle: its vertex normals would cancel to zero (NaN in the shaders)."""
    (tmp_path / "two_sided.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n")
    mesh = load_scene(mesh_scene(tmp_path, "two_sided.obj")).root.find("M").mesh
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0)
    np.testing.assert_allclose(np.abs(mesh.normals[:, 2]), 1.0)


def test_mesh_file_triangles_with_vertices_that_are_not_finite_are_dropped_with_one_warning(tmp_path):
    (tmp_path / "nan.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n")
    with pytest.warns(VctWarning, match="nan.obj: 1 triangle dropped") as record:
        mesh = load_scene(mesh_scene(tmp_path, "nan.obj")).root.find("M").mesh
    assert len(record) == 1
    assert len(mesh.indices) == 1
    assert np.all(np.isfinite(mesh.positions)) and np.all(np.isfinite(mesh.normals))


def test_loading_a_mesh_file_prints_nothing(tmp_path, capfd):
    """Vertex normals are computed without trimesh's sparse-matrix path, which logs a traceback
    to stderr when scipy is missing."""
    load_scene(mesh_scene(tmp_path, "meshes/tetrahedron.obj"))
    assert capfd.readouterr() == ("", "")


def test_mesh_file_whose_triangles_all_have_zero_area_holds_no_triangles(tmp_path):
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    with pytest.raises(SceneError, match='objects\\[0\\] "M".file: flat.obj: holds no triangles'):
        load_scene(mesh_scene(tmp_path, "flat.obj"))


# ---- the references in ../shared/reference ---------------------------------------------------

def test_a_missing_reference_skips_with_the_reason_in_a_users_clone(tmp_path, monkeypatch):
    monkeypatch.delenv(REQUIRE_REFERENCES, raising=False)
    with pytest.raises(pytest.skip.Exception, match="missing.npy is not available"):
        reference_file(tmp_path / "missing.npy")


def test_a_missing_reference_fails_where_references_are_required(tmp_path, monkeypatch):
    monkeypatch.setenv(REQUIRE_REFERENCES, "1")
    with pytest.raises(pytest.fail.Exception, match="missing.npy is not available, and VCT_REQUIRE_REFERENCES=1 requires it"):
        reference_file(tmp_path / "missing.npy")


def test_ci_requires_the_references():
    """.ci/run turns a missing reference into a failure, not a skip."""
    assert f"export {REQUIRE_REFERENCES}=1" in (ROOT / ".ci" / "run").read_text()
