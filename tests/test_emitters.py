"""Emissive surfaces as area lights (engine/scene/emitters.py, GL-free): which triangles emit, how
they are grouped into patches that share a visibility cone, and what radiance each carries."""
import numpy as np
import pytest

from engine.scene.emitters import frame_emitters
from engine.scene.model import Camera, Material, Node, Scene, Texture, box_mesh, quad_mesh
from engine.scene.table import SceneTable

PANEL = [[-0.25, 0.99, 0.25], [-0.25, 0.99, -0.25], [0.25, 0.99, -0.25], [0.25, 0.99, 0.25]]  # facing down


def emitters_of(*nodes):
    camera = Camera(np.array([0.0, 0.0, 3.0]), np.zeros(3), np.array([0.0, 1.0, 0.0]), 60.0, 64, 64)
    scene = Scene("test", Node("root", children=list(nodes)), camera, {})
    table = SceneTable()
    table.sync(scene)
    return frame_emitters([table.draw(index) for index in table.emissive_draws()])


def lamp(emission=(16.0, 16.0, 16.0), **fields):
    return Material("lamp", albedo=np.zeros(3), emission=np.array(emission, float), **fields)


def test_a_quad_lamp_is_one_patch_of_two_triangles_facing_its_way():
    emitters = emitters_of(Node("panel", mesh=quad_mesh(PANEL), material=lamp()))
    assert emitters.count == 1 and len(emitters.triangles) == 2
    patch = emitters.patches[0]
    np.testing.assert_allclose(patch["sphere"], [0.0, 0.99, 0.0, np.sqrt(2) * 0.25], atol=1e-6)
    np.testing.assert_allclose(patch["plane"], [0.0, -1.0, 0.0, 0.0], atol=1e-6)  # flat, facing down
    assert tuple(patch["triangles"][:2]) == (0, 2)
    np.testing.assert_allclose(emitters.triangles["radiance"][:, :3], 16.0)
    for t in emitters.triangles:  # the right-hand rule gives each triangle the panel's facing
        normal = np.cross(t["b"][:3] - t["a"][:3], t["c"][:3] - t["a"][:3])
        assert normal[1] < 0 and abs(normal[0]) + abs(normal[2]) < 1e-9


def test_a_glowing_box_is_six_patches_one_per_face_and_follows_its_transform():
    box = Node("box", translation=np.array([0.5, -0.8, 0.0]), scale=np.array([0.4, 0.4, 0.4]),
               mesh=box_mesh(), material=lamp((8.0, 7.2, 5.6)))
    emitters = emitters_of(box)
    assert emitters.count == 6 and len(emitters.triangles) == 12
    normals = sorted(tuple(np.round(p["plane"][:3]).astype(int)) for p in emitters.patches)
    assert normals == sorted([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)])
    for p in emitters.patches:  # each face's centre lies 0.2 m out from the box's centre along its normal
        np.testing.assert_allclose(p["sphere"][:3], np.array([0.5, -0.8, 0.0]) + 0.2 * p["plane"][:3], atol=1e-6)
        assert p["plane"][3] == pytest.approx(0.0, abs=1e-6)
    assert sorted(int(p["triangles"][0]) for p in emitters.patches) == list(range(0, 12, 2))


def test_surfaces_that_do_not_emit_are_not_emitters():
    wall = Node("wall", mesh=quad_mesh(PANEL), material=Material("white"))
    assert emitters_of(wall).count == 0
    assert len(emitters_of(wall).triangles) == 0


def test_an_emissive_texture_gives_each_triangle_the_decoded_mean_of_its_texels():
    """emission x texture: sRGB 188 decodes to 0.5029; a texture of two colours split along u
    gives a triangle covering both halves their mean over its area."""
    image = np.zeros((4, 4, 3), np.uint8)
    image[:, :2] = (188, 0, 0)  # left half: u < 0.5
    image[:, 2:] = (0, 188, 0)
    painting = Texture("painting", image, srgb=True, wrap_s="CLAMP_TO_EDGE", wrap_t="CLAMP_TO_EDGE")
    mesh = quad_mesh(PANEL)
    mesh.texcoords = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    emitters = emitters_of(Node("panel", mesh=mesh, material=lamp((2.0, 2.0, 2.0), emissive_texture=painting)))
    decoded = ((188 / 255 + 0.055) / 1.055) ** 2.4
    total = emitters.triangles["radiance"][:, :3].sum(axis=0)
    # The two triangles together hold the texture's mean twice: 2 x emission x decoded x 1/2 per channel.
    np.testing.assert_allclose(total, [2.0 * decoded, 2.0 * decoded, 0.0], rtol=0.1)
    assert np.all(emitters.triangles["radiance"][:, 2] == 0.0)
