"""Blended surfaces (alphaMode BLEND): drawn over what lies behind them in any order, a pane of
alpha a showing a of its own light and 1 - a of what is behind it; hidden behind opaque
surfaces; in the shadow maps and the voxels stopping about a of the light that crosses them."""
import numpy as np
import pytest

import engine
from engine import Camera, Light, Material, Node, Scene
from engine.scene.model import quad_mesh


def wall_and_pane(pane_alpha=0.5, pane_z=1.0, pane_emission=(0.0, 2.0, 0.0)):
    """An emissive red wall at z = 0 (L = 1, 0, 0) and in front of it a pane facing the camera
    at z = pane_z, emitting `pane_emission` and reflecting nothing, of alpha `pane_alpha`,
    blended; the camera 4 m away sees the pane across the middle of the image."""
    wall = Node("Wall", mesh=quad_mesh([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]]),
                material=Material("wall", albedo=np.zeros(3), emission=np.array([1.0, 0.0, 0.0])))
    pane = Node("Pane", mesh=quad_mesh([[-0.5, -0.5, pane_z], [0.5, -0.5, pane_z], [0.5, 0.5, pane_z], [-0.5, 0.5, pane_z]]),
                material=Material("pane", albedo=np.zeros(3), emission=np.array(pane_emission), alpha=pane_alpha,
                                  alpha_mode="BLEND", specular=0.0))
    camera = Camera(np.array([0.0, 0.0, 4.0]), np.zeros(3), np.array([0.0, 1.0, 0.0]), 40.0, 64, 64)
    return Scene("pane", Node("root", children=[wall, pane]), camera)


@pytest.mark.parametrize("mode", ["direct", "gi"])
def test_a_pane_of_alpha_half_shows_half_its_own_light_and_half_of_what_is_behind(mode):
    scene = wall_and_pane()
    with engine.Renderer(64, 64) as r:
        image = r.render(scene, mode=mode, grid=32)
    centre = image[28:36, 28:36].reshape(-1, 3)
    np.testing.assert_allclose(centre.mean(axis=0), [0.5, 1.0, 0.0], atol=0.02)
    np.testing.assert_allclose(image[2:6, 2:6].reshape(-1, 3).mean(axis=0), [1.0, 0.0, 0.0], atol=0.02)  # the wall alone


@pytest.mark.parametrize("alpha", [0.0, 0.25, 1.0])
def test_alpha_sets_how_much_of_the_pane_covers_what_is_behind(alpha):
    with engine.Renderer(64, 64) as r:
        image = r.render(wall_and_pane(pane_alpha=alpha), mode="direct")
    np.testing.assert_allclose(image[28:36, 28:36].reshape(-1, 3).mean(axis=0), [1 - alpha, 2 * alpha, 0.0], atol=0.02)


def test_a_pane_behind_an_opaque_surface_is_hidden():
    """The wall in front of the pane: the G-buffer's depth hides the pane."""
    with engine.Renderer(64, 64) as r:
        image = r.render(wall_and_pane(pane_z=-1.0), mode="direct")
    np.testing.assert_allclose(image[28:36, 28:36].reshape(-1, 3).mean(axis=0), [1.0, 0.0, 0.0], atol=1e-3)


def test_two_panes_in_either_order_give_the_same_image():
    """Order-independent: the draws' order in the scene does not change the image."""
    scene = wall_and_pane()
    second = Node("Second", mesh=quad_mesh([[-0.5, -0.5, 2.0], [0.5, -0.5, 2.0], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]),
                  material=Material("blue", albedo=np.zeros(3), emission=np.array([0.0, 0.0, 2.0]), alpha=0.5,
                                    alpha_mode="BLEND", specular=0.0))
    images = []
    for order in (lambda c: c.append(second), lambda c: c.insert(0, second)):
        scene = wall_and_pane()
        order(scene.root.children)
        with engine.Renderer(64, 64) as r:
            images.append(r.render(scene, mode="direct"))
    assert np.array_equal(images[0], images[1])
    centre = images[0][28:36, 28:36].reshape(-1, 3).mean(axis=0)
    assert centre.sum() == pytest.approx(0.25 * 1.0 + 0.75 * 2.0, abs=0.05)  # 1/4 of the wall, 3/4 of the panes' light


def floor_under_a_sun(alpha=None):
    """A white floor under a sun shining down at 45 degrees along +x, and, where `alpha` is
    given, a blended pane 1 m above it over x, z in [-1, 1], whose shadow falls on x in
    [0, 2]; the camera looks straight down at x = 1.6."""
    floor = Node("Floor", mesh=quad_mesh([[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]), material=Material("floor"))
    sun = Node("Sun", light=Light("directional", np.full(3, 3.0), direction=np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0)))
    nodes = [floor, sun]
    if alpha is not None:
        nodes.append(Node("Pane", mesh=quad_mesh([[-1, 1, 1], [1, 1, 1], [1, 1, -1], [-1, 1, -1]]),
                          material=Material("glass", alpha=alpha, alpha_mode="BLEND", double_sided=True)))
    camera = Camera(np.array([1.6, 8.0, 0.0]), np.array([1.6, 0.0, 0.0]), np.array([0.0, 0.0, -1.0]), 20.0, 64, 64)
    return Scene("shade", Node("root", children=nodes), camera)


@pytest.mark.parametrize("alpha", [0.25, 0.75])
def test_a_blended_pane_lets_about_one_minus_alpha_of_the_direct_light_through(alpha):
    """The floor in the pane's shadow (and not seen through the pane) gets about 1 - alpha of
    the sun's light: its shadow texels are dissolved with probability 1 - alpha."""
    with engine.Renderer(64, 64) as r:
        open_sky = r.render(floor_under_a_sun(), mode="direct")[..., 0]
        shaded = r.render(floor_under_a_sun(alpha), mode="direct")[..., 0]
        positions = r.positions()
    in_shadow = (positions[..., 0] > 1.3) & (positions[..., 0] < 1.9) & (np.abs(positions[..., 2]) < 0.8)
    assert in_shadow.sum() > 300
    assert (shaded[in_shadow] / open_sky[in_shadow]).mean() == pytest.approx(1.0 - alpha, abs=0.1)


@pytest.mark.parametrize("alpha", [0.3, 0.8])
def test_a_blended_pane_is_alpha_opaque_in_its_voxels(alpha):
    """The voxels carry a blended surface's opacity (the normal volume's a): a pane of alpha a
    is a opaque to the cones, and an opaque wall 1, where they cover a voxel's face (the voxels
    their edges cross, that share of it: here half, their edges passing through voxel centres;
    196 of the pane's 256 voxels read a, none more)."""
    scene = wall_and_pane(pane_alpha=alpha, pane_z=1.0)
    with engine.Renderer(32, 32) as r:
        r.render(scene, mode="voxels", grid=64)
        normal = r.voxels("normal")
        layout = r.voxel_layout
    lo, size = layout.level_bounds(0)[0], layout.voxel_size
    pane = normal[int((1.0 - lo[2]) / size) - 1:int((1.0 - lo[2]) / size) + 2, ..., 3]
    wall = normal[int((0.0 - lo[2]) / size) - 1:int((0.0 - lo[2]) / size) + 2, ..., 3]
    covered = pane[pane > 0]
    assert np.all(covered <= alpha + 0.01) and np.count_nonzero(np.abs(covered - alpha) <= 0.01) > 150
    assert np.all(wall <= 1.0) and np.count_nonzero(wall == 1.0) > 3000
