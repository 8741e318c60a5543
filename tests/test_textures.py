"""Textures on the GPU: materials read from files are sampled the right way up and in linear
colour in the image, cut out where alpha-tested in the image, the shadow maps and the voxels,
and carried into the voxels (a textured curtain bleeds its colour)."""
import json

import numpy as np
import pytest

import engine
from conftest import SCENES
from test_mesh_files import QUAD_INDICES, QUAD_POSITIONS, QUAD_TEXCOORDS, Gltf, png

# A 2x3 texture (2 wide, 3 tall), sRGB; every texel differs, and mid values show the decoding.
TEXELS = np.array([[[255, 0, 0], [0, 255, 0]],
                   [[128, 128, 128], [0, 0, 255]],
                   [[255, 255, 0], [64, 200, 32]]], np.uint8)


def srgb_to_linear(values):
    c = np.asarray(values, float) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def write_scene(tmp_path, objects, lights=(), camera=None):
    spec = {"camera": camera or {"position": [0.5, 0.5, 1.2], "look_at": [0.5, 0.5, 0.0], "vertical_fov_deg": 46.0,
                                 "width": 96, "height": 96},
            "materials": {"white": {"albedo": [0.8, 0.8, 0.8]}},
            "objects": list(objects), "lights": list(lights)}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(spec))
    return engine.load_scene(path)


def painted_gltf(path):
    """One node with two primitives: the unit quad (x, y in 0..1, facing +z) painted with
    TEXELS, and below it a plain blue quad of a second material."""
    g = Gltf()
    painted = g.add("materials", {"name": "Painted", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": g.texture(g.image(png(TEXELS)))}, "metallicFactor": 0.0}})
    plain = g.add("materials", {"name": "Plain", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.9, 1.0],
                                                                          "metallicFactor": 0.0}})
    below = {"POSITION": g.accessor(QUAD_POSITIONS - [0.0, 1.1, 0.0]), "NORMAL": g.accessor(np.tile([0, 0, 1], (4, 1))),
             "TEXCOORD_0": g.accessor(QUAD_TEXCOORDS)}
    mesh = g.add("meshes", {"primitives": [g.quad(painted),
                                           {"attributes": below, "indices": g.accessor(QUAD_INDICES, 5125), "material": plain}]})
    g.doc["scenes"][0]["nodes"].append(g.add("nodes", {"name": "Painting", "mesh": mesh}))
    return g.write(path)


def test_a_gltf_texture_shows_the_right_way_up_in_linear_colour(tmp_path):
    """glTF texture coordinate (0, 0) is the image's top-left: texel (row r, column c) of the
    2x3 base-colour texture shows at row r, column c of the quad as seen from its front, with
    its sRGB value decoded to linear; the second material's quad shows its own colour."""
    painted_gltf(tmp_path / "painted.glb")
    scene = write_scene(tmp_path, [{"name": "Model", "type": "mesh", "file": "painted.glb"}],
                        camera={"position": [0.5, 0.0, 2.6], "look_at": [0.5, 0.0, 0.0], "vertical_fov_deg": 50.0,
                                "width": 128, "height": 128})
    with engine.Renderer(128, 128) as r:
        albedo = r.render(scene, mode="albedo")
        position = r.positions()
    on_painting = position[..., 1] > 0.0
    for row in range(3):
        for column in range(2):
            # The centre of texel (row, column) on the quad: x = (column + 0.5) / 2, y = 1 - (row + 0.5) / 3.
            target = np.array([(column + 0.5) / 2.0, 1.0 - (row + 0.5) / 3.0])
            distance = np.where(on_painting, np.linalg.norm(position[..., :2] - target, axis=2), np.inf)
            pixel = np.unravel_index(np.argmin(distance), distance.shape)
            assert distance[pixel] < 0.02
            assert albedo[pixel] == pytest.approx(srgb_to_linear(TEXELS[row, column]), abs=0.05), (row, column)
    plain = position[..., 1] < -0.3  # NaN where no surface
    assert plain.sum() > 500
    assert np.allclose(albedo[plain], [0.1, 0.2, 0.9], atol=0.005)


def grille_gltf(path, alpha_mode):
    """A 1 m grille: the unit quad laid flat (facing down) with a 4x4 checker of alpha 0/1."""
    g = Gltf()
    checker = (np.indices((4, 4)).sum(axis=0) % 2 * 255).astype(np.uint8)
    rgba = np.dstack([np.full((4, 4, 3), 200, np.uint8), checker])
    grille = g.add("materials", {"name": "Grille", "alphaMode": alpha_mode, "doubleSided": True,
                                 "pbrMetallicRoughness": {"baseColorTexture": {"index": g.texture(g.image(png(rgba)))},
                                                          "metallicFactor": 0.0}})
    mesh = g.add("meshes", {"primitives": [g.quad(grille)]})
    # Turned 90 degrees about x: the quad's +z normal points down, its plane is horizontal.
    g.doc["scenes"][0]["nodes"].append(g.add("nodes", {"name": "Grille", "mesh": mesh, "translation": [-0.5, 1.0, -0.5],
                                                        "rotation": [0.7071068, 0.0, 0.0, 0.7071068]}))
    return g.write(path)


def grille_scene(tmp_path, alpha_mode):
    grille_gltf(tmp_path / f"grille_{alpha_mode}.glb", alpha_mode)
    floor = {"name": "Floor", "type": "quad", "material": "white",
             "vertices": [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]]}
    # The sun at 45 degrees casts the grille's shadow 1 m to its side, on open floor.
    sun = {"name": "Sun", "type": "directional", "direction": [1.0, -1.0, 0.0], "irradiance": [3.0, 3.0, 3.0]}
    return write_scene(tmp_path, [floor, {"name": "Grille", "type": "mesh", "file": f"grille_{alpha_mode}.glb"}], [sun],
                       camera={"position": [0.5, 3.0, 0.01], "look_at": [0.5, 0.0, 0.0], "vertical_fov_deg": 50.0,
                               "width": 128, "height": 128})


def test_an_alpha_masked_grille_casts_a_shadow_with_holes_and_voxelizes_with_holes(tmp_path):
    """A grille cut out by a checker of alpha, under a sun at 45 degrees: its shadow on the
    floor is a checker too, lit where the gaps let light through and dark under the bars (an
    opaque grille's shadow is dark all over), and the grille's voxels cover only its bars."""
    def floor_in_shadow(r, scene):
        direct = r.render(scene, mode="direct")[..., 0]
        position = r.positions()
        x, y, z = position[..., 0], position[..., 1], position[..., 2]
        return direct[(np.abs(y) < 1e-3) & (x > 0.6) & (x < 1.4) & (np.abs(z) < 0.4)]

    with engine.Renderer(128, 128) as r:
        masked_scene, opaque_scene = grille_scene(tmp_path, "MASK"), grille_scene(tmp_path, "OPAQUE")
        masked = floor_in_shadow(r, masked_scene)
        opaque = floor_in_shadow(r, opaque_scene)
        r.render(masked_scene, mode="voxel-albedo", grid=32)
        voxels = r.voxels("albedo")[..., 3] > 0
        r.render(opaque_scene, mode="voxel-albedo", grid=32)
        opaque_voxels = r.voxels("albedo")[..., 3] > 0
        region_floor, voxel_size = r.voxel_layout.level_bounds(0)[0][1], r.voxel_layout.voxel_size
    lit = 0.8 / np.pi * 3.0 * np.cos(np.radians(45.0))
    assert len(masked) > 1000 and len(opaque) > 1000
    assert np.all(opaque < 0.05 * lit)
    assert (masked > 0.9 * lit).mean() == pytest.approx(0.5, abs=0.15)
    assert (masked < 0.1 * lit).mean() == pytest.approx(0.5, abs=0.15)
    # The voxel layer of the grille's plane, y = 1.
    layer = int((1.0 - region_floor) / voxel_size)
    inside = np.s_[:, layer, :]
    assert voxels[inside].sum() == pytest.approx(0.5 * opaque_voxels[inside].sum(), rel=0.25)


@pytest.mark.parametrize("grid", [64])
def test_sponza_voxels_carry_the_red_green_and_blue_of_its_curtains(grid):
    """Sponza's textured curtains reach its voxels: the voxel-albedo view shows saturated red,
    green and blue (a flat grey material would show none)."""
    scene = engine.load_scene(SCENES / "sponza.json")
    with engine.Renderer(128, 128) as r:
        albedo = r.render(scene, mode="voxel-albedo", grid=grid)
    red, green, blue = (albedo[..., k] for k in range(3))
    assert ((red > 2.5 * green) & (red > 2.5 * blue)).sum() > 30
    assert ((green > 1.6 * red) & (green > 1.6 * blue)).sum() > 30
    assert ((blue > 2.0 * red) & (blue > 1.3 * green)).sum() > 30


def test_an_emissive_texture_lights_the_room_in_its_colour(tmp_path):
    """A lamp whose colour comes from its emissive texture (orange, sRGB) and a black base
    colour, facing down over a white floor, lit by nothing else: the floor under it receives
    orange light, as the lamp's direct light and with the light it bounces (its red over green
    over blue as the texture's, decoded)."""
    g = Gltf()
    orange = np.full((2, 2, 3), (255, 128, 0), np.uint8)
    lamp = g.add("materials", {"name": "Lamp", "emissiveFactor": [1.0, 1.0, 1.0],
                               "emissiveTexture": {"index": g.texture(g.image(png(orange)))},
                               "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 8.0}},
                               "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0}})
    mesh = g.add("meshes", {"primitives": [g.quad(lamp)]})
    g.doc["scenes"][0]["nodes"].append(g.add("nodes", {"name": "Lamp", "mesh": mesh, "translation": [-0.5, 1.0, -0.5],
                                                        "rotation": [0.7071068, 0.0, 0.0, 0.7071068]}))  # facing down
    g.write(tmp_path / "lamp.glb")
    floor = {"name": "Floor", "type": "quad", "material": "white",
             "vertices": [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]]}
    scene = write_scene(tmp_path, [floor, {"name": "Lamp", "type": "mesh", "file": "lamp.glb"}],
                        camera={"position": [0.0, 0.6, 2.0], "look_at": [0.0, 0.0, 0.0], "vertical_fov_deg": 40.0,
                                "width": 64, "height": 64})
    with engine.Renderer(64, 64) as r:
        gi = r.render(scene, grid=64)
        direct = r.render(scene, mode="direct")
    expected = srgb_to_linear([255, 128, 0])  # the texture's linear colour: 1, 0.216, 0
    for image in (direct, gi):  # the lamp's direct light, and with the light the floor bounces
        red, green, blue = image[40:60, 24:40].reshape(-1, 3).mean(axis=0)
        assert red > 0.05 and blue < 1e-3 * red
        assert green / red == pytest.approx(expected[1], rel=0.1)


def test_a_normal_map_tilts_the_shading_normal_in_its_tangent_frame_and_other_materials_keep_theirs(tmp_path):
    """A quad facing +z whose normal texture holds (0.6, 0, 0.8) in tangent space (tangent along
    +u, which is +x) shows the normal (0.6, 0, 0.8) in the G-buffer; a quad beside it without a
    normal map shows its own +z. (The two are drawn by the G-buffer's two programs, with and
    without the tangent, in one frame.)"""
    g = Gltf()
    texel = np.round((0.5 * np.array([0.6, 0.0, 0.8]) + 0.5) * 255).astype(np.uint8)
    bumpy = g.add("materials", {"name": "Bumpy", "normalTexture": {"index": g.texture(g.image(png(np.tile(texel, (2, 2, 1)))))}})
    plain = g.add("materials", {"name": "Plain"})
    beside = {"POSITION": g.accessor(QUAD_POSITIONS - [1.1, 0.0, 0.0]), "NORMAL": g.accessor(np.tile([0, 0, 1], (4, 1))),
              "TEXCOORD_0": g.accessor(QUAD_TEXCOORDS)}
    mesh = g.add("meshes", {"primitives": [g.quad(bumpy), {"attributes": beside, "indices": g.accessor(QUAD_INDICES, 5125),
                                                           "material": plain}]})
    g.doc["scenes"][0]["nodes"].append(g.add("nodes", {"name": "Quads", "mesh": mesh}))
    g.write(tmp_path / "quads.glb")
    scene = write_scene(tmp_path, [{"name": "Model", "type": "mesh", "file": "quads.glb"}],
                        camera={"position": [-0.05, 0.5, 2.6], "look_at": [-0.05, 0.5, 0.0], "vertical_fov_deg": 50.0,
                                "width": 128, "height": 128})
    with engine.Renderer(128, 128) as r:
        normal = 2.0 * r.render(scene, mode="normal") - 1.0
    mapped, unmapped = normal[64, 88], normal[64, 40]  # the quad at x 0..1, the one at x -1.1..-0.1
    np.testing.assert_allclose(mapped, [0.6, 0.0, 0.8], atol=0.02)
    np.testing.assert_allclose(unmapped, [0.0, 0.0, 1.0], atol=1e-3)
