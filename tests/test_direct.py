"""Direct lighting: radiometry against Mitsuba and analytic formulas, shadows, G-buffer views."""
import json
import math

import numpy as np
import pytest

import engine
from conftest import rel_mae, SCENES


def test_direct_light_matches_the_path_traced_reference(renderer, cornell, reference):
    """Lambert k_d/pi with a W/sr point light and inverse-square falloff reproduces Mitsuba's
    direct-only image: relative MAE at most 0.05."""
    radiance = renderer.render(cornell, mode="direct")
    assert radiance.shape == (256, 256, 3) and radiance.dtype == np.float32
    error = rel_mae(radiance, reference("direct"))
    assert error <= 0.05, f"relMAE {error:.4f}"


def plane_scene(tmp_path, light_position, intensity):
    """A 4x4 white floor at y=0 seen from above, one point light."""
    spec = {
        "camera": {"position": [0.0, 3.0, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
                   "vertical_fov_deg": 60.0, "width": 64, "height": 64},
        "materials": {"white": {"albedo": [0.5, 0.6, 0.7]}},
        "objects": [{"name": "Floor", "type": "quad", "material": "white",
                     "vertices": [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]]}],
        "lights": [{"name": "Lamp", "type": "point", "position": light_position, "intensity": intensity}],
    }
    path = tmp_path / "plane.json"
    path.write_text(json.dumps(spec))
    return engine.load_scene(path)


def test_plane_under_point_light_matches_inverse_square_law(tmp_path):
    """L = albedo/pi * I cos(theta) / d^2 at several pixels, within 1%."""
    light = np.array([0.3, 1.0, -0.2])
    intensity = np.array([2.0, 3.0, 4.0])
    scene = plane_scene(tmp_path, light.tolist(), intensity.tolist())
    with engine.Renderer(64, 64) as r:
        radiance = r.render(scene, mode="direct")
    albedo = np.array([0.5, 0.6, 0.7])
    half_extent = 3.0 * math.tan(math.radians(30.0))  # camera 3 above the floor, 60 degree fov
    for row, col in [(32, 32), (10, 50), (50, 12), (5, 5), (60, 40)]:
        # Floor point under the pixel centre: right = +x, up on screen = -z.
        x_ndc, y_ndc = (col + 0.5) / 32.0 - 1.0, 1.0 - (row + 0.5) / 32.0
        p = np.array([x_ndc * half_extent, 0.0, -y_ndc * half_extent])
        to_light = light - p
        d2 = to_light @ to_light
        cos_theta = to_light[1] / math.sqrt(d2)
        expected = albedo / math.pi * intensity * cos_theta / d2
        assert np.allclose(radiance[row, col], expected, rtol=0.01), (row, col, radiance[row, col], expected)


def test_point_light_has_no_range_cutoff_unless_given(tmp_path):
    """Without `range` the falloff is pure inverse square at any distance; with a range light
    stops at that distance."""
    far = plane_scene(tmp_path, [0.0, 1.0, 0.0], [1.0, 1.0, 1.0])
    with engine.Renderer(64, 64) as r:
        corner = r.render(far, mode="direct")[2, 2]
        far.root.find("Lamp").light.range = 1.5
        cut = r.render(far, mode="direct")[2, 2]
    assert corner.min() > 0.0
    assert np.all(cut == 0.0)


def test_shadow_behind_tall_box_is_dark_and_open_floor_is_lit(renderer, cornell, reference):
    """A floor point hidden from the light by the tall box gets no direct light; an open one does."""
    radiance = renderer.render(cornell, mode="direct")
    ref = reference("direct")
    # Pixels chosen where the reference is fully shadowed / fully lit.
    shadowed = (250, 5)
    lit = (255, 142)
    assert ref[shadowed].max() < 1e-3 and ref[lit].min() > 0.1
    assert radiance[shadowed].max() < 0.01 * radiance[lit].max()
    assert radiance[lit] == pytest.approx(ref[lit], rel=0.02)


def test_shadows_neither_acne_nor_peter_pan(renderer, cornell, reference):
    """Every directly lit reference pixel is lit here too (no acne) and every pixel in the
    reference's umbra is dark here (no light leaking under the boxes)."""
    radiance = renderer.render(cornell, mode="direct").mean(axis=2)
    ref = reference("direct").mean(axis=2)
    interior = np.zeros_like(ref, dtype=bool)
    interior[2:-2, 2:-2] = True
    # Away from shadow edges: erode lit and umbra masks by a few pixels.
    from numpy.lib.stride_tricks import sliding_window_view
    def erode(mask, k=3):
        padded = np.pad(mask, k, constant_values=False)
        return sliding_window_view(padded, (2 * k + 1, 2 * k + 1)).all(axis=(2, 3))
    window = sliding_window_view(np.pad(ref, 2, mode="edge"), (5, 5))
    smooth = window.max(axis=(2, 3)) - window.min(axis=(2, 3)) < 0.25 * ref  # no silhouette edge near
    lit = erode(ref > 0.02) & smooth & interior
    umbra = erode(ref < 1e-3, k=1) & interior
    assert lit.sum() > 10000 and umbra.sum() > 20
    assert np.all(radiance[lit] > 0.5 * ref[lit]), "shadow acne: lit pixels came out dark"
    assert np.all(radiance[umbra] < 0.005), "light where the reference has full shadow"


def test_normal_view_shows_inward_normals_on_each_wall(renderer, cornell):
    """normal mode encodes 0.5 n + 0.5; every wall's normal points into the room."""
    encoded = renderer.render(cornell, mode="normal")
    normals = encoded * 2.0 - 1.0
    expected = {
        "left wall": ((128, 2), (1, 0, 0)),
        "right wall": ((128, 253), (-1, 0, 0)),
        "floor": ((255, 142), (0, 1, 0)),
        "ceiling": ((1, 128), (0, -1, 0)),
        "back wall": ((60, 200), (0, 0, 1)),
    }
    for name, (pixel, normal) in expected.items():
        assert np.allclose(normals[pixel], normal, atol=0.02), (name, normals[pixel])


def test_albedo_and_depth_views(renderer, cornell):
    """albedo mode shows the material albedo; depth mode grows with distance from the camera."""
    albedo = renderer.render(cornell, mode="albedo")
    assert np.allclose(albedo[128, 2], [0.65, 0.05, 0.05], atol=0.01)
    assert np.allclose(albedo[128, 253], [0.12, 0.45, 0.15], atol=0.01)
    depth = renderer.render(cornell, mode="depth")[..., 0]
    assert depth[60, 200] > depth[150, 60] > 0.0  # back wall behind the tall box


def test_emissive_surface_shows_its_radiance(tmp_path):
    """A surface with emission radiance Le shows Le from its front side (no lights needed)."""
    spec = json.loads((SCENES / "cornell_box.json").read_text())
    spec["materials"]["lamp"] = {"albedo": [0.0, 0.0, 0.0], "emission": [2.0, 1.5, 1.0]}
    spec["objects"][5]["material"] = "lamp"  # the far wall, facing the camera
    spec["lights"] = []
    path = tmp_path / "emissive.json"
    path.write_text(json.dumps(spec))
    with engine.Renderer(64, 64) as r:
        radiance = r.render(engine.load_scene(path), mode="direct")
    assert np.allclose(radiance[20, 40], [2.0, 1.5, 1.0], rtol=1e-3)


def test_tone_mapping_curves_and_srgb(renderer, cornell):
    """The PNG path applies exposure, the chosen curve and sRGB: brighter exposure gives
    brighter pixels, and 'none' clips radiance * exposure before encoding."""
    renderer.render(cornell, mode="direct", tonemap="none", exposure=1.0)
    base = renderer.tonemapped().astype(int)
    renderer.render(cornell, mode="direct", tonemap="none", exposure=4.0)
    bright = renderer.tonemapped().astype(int)
    assert bright.mean() > base.mean()
    radiance = renderer.render(cornell, mode="direct", tonemap="none", exposure=1.0)
    x = np.clip(radiance[255, 142], 0, 1)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    assert np.allclose(base[255, 142], np.round(srgb * 255), atol=1)
    for curve in ("aces", "reinhard"):
        renderer.render(cornell, mode="direct", tonemap=curve)
        assert renderer.tonemapped().max() <= 255


def test_spot_light_lights_its_cone_only(tmp_path):
    """Inside the inner angle a spot light is a point light (I cos / d^2); outside the outer
    angle it gives nothing."""
    scene = plane_scene(tmp_path, [0.0, 1.0, 0.0], [2.0, 2.0, 2.0])
    lamp = scene.root.find("Lamp").light
    lamp.type, lamp.direction = "spot", np.array([0.0, -1.0, 0.0])
    lamp.inner_angle_deg, lamp.outer_angle_deg = 20.0, 30.0
    with engine.Renderer(64, 64) as r:
        radiance = r.render(scene, mode="direct")
    albedo = np.array([0.5, 0.6, 0.7])
    assert np.allclose(radiance[32, 32], albedo / math.pi * 2.0, rtol=0.01)  # straight below, d = 1
    assert np.all(radiance[2, 2] == 0.0)  # about 70 degrees off the axis


def test_directional_light_gives_uniform_irradiance(tmp_path):
    """A directional light of irradiance E at angle theta gives L = albedo/pi * E cos(theta)
    everywhere on an open floor."""
    scene = plane_scene(tmp_path, [0.0, 1.0, 0.0], [1.0, 1.0, 1.0])
    lamp = scene.root.find("Lamp").light
    direction = np.array([0.6, -0.8, 0.0])
    lamp.type, lamp.direction, lamp.intensity = "directional", direction, np.array([3.0, 3.0, 3.0])
    with engine.Renderer(64, 64) as r:
        radiance = r.render(scene, mode="direct")
    expected = np.array([0.5, 0.6, 0.7]) / math.pi * 3.0 * 0.8
    assert np.allclose(radiance[8:56, 8:56].reshape(-1, 3), expected, rtol=0.01)


@pytest.mark.parametrize("field", [60.0, 600.0])
def test_a_thin_post_near_the_camera_casts_a_sharp_sun_shadow_in_a_wide_scene(tmp_path, field):
    """The sun's shadow views follow the camera, as many as the scene's size asks for: on a field
    60 m or 600 m wide, a post 6 cm thick seen from 4 m casts a shadow as dark as the post is
    solid and as wide as the post (3.3 pixels of 1.8 cm). One view of the whole field (16 cm or
    1.6 m texels) loses it; three cascades over the 600 m field (their finest 94 m deep) too."""
    half = field / 2.0
    spec = {
        "camera": {"position": [0.75, 4.0, 0.0], "look_at": [0.75, 0.0, 0.0], "up": [0.0, 0.0, -1.0],
                   "vertical_fov_deg": 60.0, "width": 256, "height": 256},
        "materials": {"white": {"albedo": [0.5, 0.5, 0.5]}},
        "objects": [{"name": "Field", "type": "quad", "material": "white",
                     "vertices": [[-half, 0, -half], [-half, 0, half], [half, 0, half], [half, 0, -half]]},
                    {"name": "Post", "type": "box", "material": "white", "center": [0.0, 1.0, 0.0], "size": [0.06, 2.0, 0.06]}],
        "lights": [{"name": "Sun", "type": "directional", "direction": [0.6, -0.8, 0.0], "irradiance": [3.0, 3.0, 3.0]}],
    }
    path = tmp_path / "field.json"
    path.write_text(json.dumps(spec))
    with engine.Renderer(256, 256) as r:
        luminance = r.render(engine.load_scene(path), mode="direct").mean(axis=2)
    lit = 0.5 / math.pi * 3.0 * 0.8
    pixel = 2.0 * 4.0 * math.tan(math.radians(30.0)) / 256  # metres of field per pixel
    # The shadow runs along +x from the post's foot to x = 1.5 m; across it, along z (image rows).
    for x in (0.4, 0.8, 1.2):
        column = 128 + round((x - 0.75) / pixel)
        across = luminance[:, column]
        shadowed = np.flatnonzero(across < 0.5 * lit)
        assert across.min() < 0.05 * lit and 2 <= len(shadowed) <= 5, (x, across.min() / lit, len(shadowed))
        assert np.all(np.abs(shadowed - 127.5) < 4), shadowed  # about z = 0
