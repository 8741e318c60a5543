"""Scenes of our own against their path-traced references (scenes/references, made with
tools/reference.py): textured glTF materials with alpha cut-outs, and light from emissive
surfaces, at grid 128, the images compared pixel for pixel (relative MAE, luminance ratio)."""
import numpy as np
import pytest

import engine
from conftest import SCENES, luminance_ratio, rel_mae

REFERENCES = SCENES / "references"


def reference(name):
    return np.load(REFERENCES / f"{name}.npy").astype(np.float64)


def render(name, **settings):
    """Reference scene `name` (its scene file, or NAME.glb: a glTF file that is the scene)
    rendered at 256x256 with `settings`."""
    scene = engine.load_scene(REFERENCES / name if name.endswith(".glb") else REFERENCES / f"{name}.json")
    with engine.Renderer(256, 256) as r:
        return r.render(scene, **settings)


def assert_matches(image, expected, error_bound, luminance_bound):
    """Relative MAE at most `error_bound`, mean luminance within `luminance_bound` of the reference's."""
    assert rel_mae(image, expected) <= error_bound
    assert luminance_ratio(image, expected) == pytest.approx(1.0, abs=luminance_bound)


def test_textured_box_direct_light_matches_its_reference():
    """A glTF box with an asymmetric sRGB base-colour texture and an alpha-masked grille whose
    patterned shadow falls on the back wall: direct light within 5 % (relative MAE)."""
    assert_matches(render("textured_box", mode="direct"), reference("textured_box_direct"), 0.05, 0.02)


def test_textured_box_converged_gi_matches_its_reference():
    """The same scene with all bounces: the textures' colours bounce through the voxels, the
    glTF dielectrics' diffuse layers reflecting what their specular layers leave; within 10 %
    (relative MAE, measured 0.086), luminance within 5 % (1.038; a diffuse layer not reduced by
    the specular one's share came out 23 % bright)."""
    assert_matches(render("textured_box", grid=128), reference("textured_box_gi"), 0.10, 0.05)


# Measured at grid 128 (docs/ACCURACY.md): the bounds hold those figures with a margin and fail
# a renderer that averaged a lamp with the ceiling behind it (luminance 0.45), lost emitters, or
# carried their light through the diffuse cones alone (the lamp panel 0.150, the glowing box
# 0.178 / 1.174, the spheres 0.184).
EMISSIVE = {  # scene: (relMAE bound, luminance ratio bound) of the converged image
    "panel_under_ceiling": (0.04, 0.03),    # measured 0.028, 1.000
    "emissive_box_on_floor": (0.06, 0.05),  # measured 0.037, 0.975
    "coloured_panel": (0.05, 0.03),         # measured 0.030, 1.003
    # The panel over a gold and a plastic sphere: fails where the voxels absorbed what the
    # metal reflects (0.259, 0.771) instead of bouncing it on.
    "cornell_spheres": (0.07, 0.03),        # measured 0.064, 1.027
}


@pytest.mark.parametrize("name", sorted(EMISSIVE))
def test_light_from_emissive_surfaces_matches_its_reference(name):
    """Scenes lit by emissive surfaces alone (a panel 1 cm under the ceiling, a glowing box on
    the floor, an orange panel on a wall, a ceiling panel over a metal and a plastic sphere),
    all bounces through the voxels."""
    assert_matches(render(name, grid=128), reference(f"{name}_gi"), *EMISSIVE[name])


# Measured at grid 128: panel 0.0029, glowing box 0.0104 (with the tall box's shadow), orange
# panel 0.0138; luminance within 1 %. (cornell_spheres is left out: its direct image holds the
# panel's glossy reflections in the spheres, which this renderer's specular cones add in GI.)
EMITTER_DIRECT = ("panel_under_ceiling", "emissive_box_on_floor", "coloured_panel")


@pytest.mark.parametrize("name", EMITTER_DIRECT)
def test_direct_light_from_emissive_surfaces_matches_its_reference(name):
    """An emitter's direct light is Lambert's polygon formula over its triangles, shadowed by
    cones through the voxels: within 3 % of the path tracer's (relative MAE), close to the
    emitter (a floor by a glowing box, a wall under a lamp 1 cm from the ceiling) as across
    the room."""
    assert_matches(render(name, mode="direct", grid=128), reference(f"{name}_direct"), 0.03, 0.02)


# The panel's back side, in the image (rows and columns inside its outline).
THIN_PANEL_BACK = (slice(110, 245), slice(60, 195))


def test_a_thin_panel_seen_from_behind_is_lit_by_its_own_cones_like_the_path_tracer():
    """A double-sided panel whose voxels face the light, seen from its other side, which only
    reflected light reaches: no voxel faces those pixels, so their diffuse cones are traced at
    every other pixel in x and y and shared with the pixels between. The image is within 7 %
    of the path tracer (measured 0.052 at 128^3); the back side receives no direct light and
    reads 6 % dark (measured 0.938: its voxels hold the double-sided panel's two sides, the
    back one lit, gathering and seen on its own; with one side 1.076, its cones reading some of
    the front's light); a back side without its indirect light, or lit as if it faced the
    light, fails."""
    scene = engine.load_scene(REFERENCES / "thin_panel.json")
    with engine.Renderer(256, 256) as r:
        direct = r.render(scene, mode="direct")
        gi = r.render(scene, grid=128)
    expected = reference("thin_panel_gi")
    assert rel_mae(gi, expected) <= 0.07
    assert np.all(direct[THIN_PANEL_BACK] == 0.0)
    assert np.all(reference("thin_panel_direct")[THIN_PANEL_BACK] == 0.0)
    back_ratio = gi[THIN_PANEL_BACK].mean() / expected[THIN_PANEL_BACK].mean()
    assert back_ratio == pytest.approx(1.0, abs=0.12)


# Issue 21's scenes at grid 128: (relMAE bound, luminance ratio bound) of the converged image.
# The bounds are the (0.10, 5 %) where the renderer meets them, with the measured figures.
AS_AUTHORED = {
    # The Cornell box open to a uniform sky, and a room lit through a 1.2 m opening in its
    # ceiling by a sky map: the sky's light through the voxels, its bounces, the map's
    # convention. With the sky's cones reading their footprint's own level the open box came
    # out at 0.67 of the path tracer's luminance, sky_room (one level below) at 0.85; with the
    # gather's cones counting the walls beside the open top where the sky's cones see the sky
    # (both lights for that part of the hemisphere), the open box 1.045.
    "open_box_sky": (0.10, 0.025),   # measured 0.030, 1.010
    "sky_room": (0.10, 0.05),        # measured 0.082, 0.997
    # A glTF file as the whole scene: its camera, KHR lights, textures, texture transform,
    # vertex colours (rendered square, as its reference).
    "gltf_room.glb": (0.10, 0.05),   # measured 0.077, 0.967
}


@pytest.mark.parametrize("name", sorted(AS_AUTHORED))
def test_scenes_as_authored_match_their_references(name):
    """Skies and a glTF file as the scene, all bounces through the voxels."""
    assert_matches(render(name, grid=128), reference(f"{name.removesuffix('.glb')}_gi"), *AS_AUTHORED[name])


@pytest.mark.parametrize("name", ["open_box_sky", "sky_room", "gltf_room.glb", "gltf_spheres"])
def test_direct_light_of_skies_and_gltf_scenes_matches_its_reference(name):
    """Direct light alone: a sky through the voxels within 15 % (relative MAE; measured 0.036
    for the open box, 0.142 through the opening, where the cones' visibility is noisy), a
    glTF file's KHR lights and the glTF spheres' layers within 3 % (0.028, 0.023)."""
    bounds = {"open_box_sky": (0.06, 0.04), "sky_room": (0.15, 0.07), "gltf_room.glb": (0.03, 0.02), "gltf_spheres": (0.03, 0.02)}
    assert_matches(render(name, mode="direct", grid=128), reference(f"{name.removesuffix('.glb')}_direct"), *bounds[name])


def test_gltf_dielectrics_and_metals_at_three_roughnesses_match_their_reference():
    """Six glTF spheres (white dielectric and gold at roughness 0.1, 0.4, 0.8) in the Cornell
    box, seen from above: within 10 % (relMAE, measured 0.092) and 5 % (0.986). Their voxels
    pass on the layered albedo with the specular lobe's masking; without it (the lobe's albedo
    taken as F) the rough layers pass on more than they reflect, and with the diffuse cones at
    their footprint's level the floor's and walls' indirect light read dark (0.125, 0.892). A
    renderer that added the dielectrics' layers instead of splitting them would make the
    spheres' diffuse layers reflect 8 % more per bounce; the furnaces
    (tests/test_environment.py) check that split directly."""
    assert_matches(render("gltf_spheres", grid=128), reference("gltf_spheres_gi"), 0.10, 0.05)


# The ceiling and the upper walls of low_lamp, above the horizon.
UPPER_ROOM = (slice(0, 96), slice(None))


def test_light_a_lamps_pool_on_the_floor_reflects_reaches_the_room():
    """A lamp 0.2 m above the floor of the empty Cornell box: the pool of light under it lights
    the ceiling and the upper walls, whose own direct light is a tenth of what it sends them.
    Converged within 10 % (relMAE, measured 0.068) and 5 % (0.971), the upper room within 8 %
    (0.942). The six cones reading their footprint's own level took in the walls beside them
    before the pool (0.082, 0.926; the upper room 0.883; docs/DESIGN.md, "Diffuse cones read
    finer")."""
    gi, expected = render("low_lamp", grid=128), reference("low_lamp_gi")
    assert_matches(gi, expected, 0.10, 0.05)
    assert luminance_ratio(gi[UPPER_ROOM], expected[UPPER_ROOM]) == pytest.approx(1.0, abs=0.08)


def test_a_corridor_lit_by_a_lamp_reads_its_walls_light_through_tiled_cones():
    """A corridor 16 m long and open to the sky (black), lit by a lamp 2 m up (lamp_corridor):
    the lecture's six wide cones take in the lamp-lit walls beside a cone before its rays reach
    them, and the converged image at 128^3 comes out 8 % bright (relMAE 0.093, luminance
    1.083); each traced as seven narrower ones (`diffuse_cones="tiled"`), within 5 % and 2 %
    (measured 0.027, 1.007)."""
    gi = render("lamp_corridor", grid=128, diffuse_cones="tiled")
    assert_matches(gi, reference("lamp_corridor_gi"), 0.05, 0.02)


# The short box's turned front face, as the gold tall box of glossy_cornell reflects it.
REFLECTED_FACE = (slice(195, 250), slice(85, 132))


def stripe_contrast(image):
    """Contrast of vertical stripes in the reflected face: the face's mean over its rows (which
    keeps vertical stripes and averages a path tracer's noise away) against its running mean
    over 9 columns, relative to its mean."""
    profile = image[REFLECTED_FACE].mean(axis=-1).mean(axis=0)
    kernel = np.ones(9) / 9
    smooth = np.convolve(np.pad(profile, 4, mode="edge"), kernel, mode="valid")
    return np.abs(profile - smooth).mean() / profile.mean()


def test_a_flat_face_reflected_in_glossy_gold_shows_no_voxel_stairs():
    """A silver floor (roughness 0.3) and a gold tall box (0.15) under a lamp panel: the image
    within 0.10 (measured 0.084) and 5 % (0.968); in the gold box, the short box's turned face
    shows stripes of contrast 0.002, the path tracer's 0.004. Cones that counted the coverage
    of the cells they cross once saw through the face's voxel staircase where they crossed one
    voxel of it (0.020; cones reading single voxels 0.039)."""
    gi, expected = render("glossy_cornell", grid=128), reference("glossy_cornell_gi")
    assert_matches(gi, expected, 0.10, 0.05)
    assert stripe_contrast(expected) < 0.01
    assert stripe_contrast(gi) <= 0.008


# The camera's side of the thin sheet (thin_sheet.json): its front quad, below the sheet's top.
THIN_SHEET_FRONT = (slice(100, 256), slice(90, 166))


@pytest.mark.parametrize("grid, bound", [(32, 0.15), (64, 0.15), (128, 0.15)])
def test_a_sheet_lit_on_one_face_passes_on_the_light_of_that_face_alone(grid, bound):
    """Two single-sided quads 1 cm apart inside one voxel, back to back; a spot lights the back
    one alone, so every other surface is lit by what that face reflects. Each voxel keeps its
    two sides (their own normal, light and gather): the room's light is the path tracer's within
    15 % at 32^3, 64^3 and 128^3 (measured 1.129, 1.143, 1.023; with one mean normal a voxel the
    two faces cancelled and the lit one passed on 0.13, 0.07, 0.04 of it), and the camera's side
    of the sheet, which only that light reaches, within 1.5x (1.18, 1.18, 1.42: the voxel's near
    cells hold its lit side's light too)."""
    image = render("thin_sheet", grid=grid)
    expected = reference("thin_sheet_gi")
    assert not reference("thin_sheet_direct").any()  # every pixel's light is indirect
    assert luminance_ratio(image, expected) == pytest.approx(1.0, abs=bound)
    assert image[THIN_SHEET_FRONT].mean() / expected[THIN_SHEET_FRONT].mean() < 1.5


@pytest.mark.parametrize("grid", [32, 64])
def test_a_sheet_whose_faces_are_a_millimetre_apart_keeps_them_apart_on_a_coarse_grid(grid):
    """The same sheet with its quads 1 mm apart, 0.015 and 0.03 of a voxel at 32^3 and 64^3
    (two sheets 1 cm apart in a 30 m courtyard are 0.04 of a 128^3 grid's voxel): its voxels
    still keep the two faces as two sides, and the room's light is the path tracer's for the
    1 cm sheet within 15 % (measured 1.118, 1.136; faces closer than 0.05 of a voxel made one
    side, whose normals cancelled: 0.128, 0.069)."""
    scene = engine.load_scene(REFERENCES / "thin_sheet.json")
    back = next(node for node in scene.root.children if node.name == "Sheet Back")
    z = -0.2011  # 1 mm behind the front quad
    moved = engine.Node("Sheet Back", mesh=engine.quad_mesh([[0.45, -1, z], [-0.45, -1, z], [-0.45, 0.3, z], [0.45, 0.3, z]]),
                        material=back.material)
    scene.root.children = [node for node in scene.root.children if node is not back] + [moved]
    with engine.Renderer(256, 256) as r:
        image = r.render(scene, grid=grid)
    assert luminance_ratio(image, reference("thin_sheet_gi")) == pytest.approx(1.0, abs=0.15)


def test_sponzas_indirect_light_keeps_the_light_of_surfaces_back_to_back():
    """Sponza under its sky at 128^3: banners and curtains are two sheets back to back, draped,
    and a third of its bricks have an opposite face within a voxel. With a side per orientation
    (with or against a voxel's most common facing) its indirect light (GI less direct, on both
    sides) is the path tracer's within 15 %, the image within 0.15 relative MAE (measured 0.921
    and 0.138; the lecture's six wide cones alone 0.832, their coarse cells holding the lit
    face of an arcade and the dark vaults behind it together; with one sun shadow view over the
    whole courtyard instead of cascades following the camera, 0.163; with each fragment
    covering its voxel's face whole, 0.775 and 0.170; with the orientations split by the sign of
    each normal's dominant component, which mixed a banner's faces where it turns through a
    diagonal, 0.749 and 0.173; one mean normal a voxel: 0.565)."""
    scene = engine.load_scene(SCENES / "sponza.json")
    with engine.Renderer(256, 256) as r:
        direct = r.render(scene, mode="direct")
        gi = r.render(scene, grid=128)
    expected_gi, expected_direct = reference("sponza_gi"), reference("sponza_direct")
    assert luminance_ratio(gi - direct, expected_gi - expected_direct) == pytest.approx(1.0, abs=0.15)
    assert rel_mae(gi, expected_gi) <= 0.15


@pytest.mark.parametrize("grid, face_bound", [(32, 0.15), (64, 0.15), (128, 0.4)])
def test_a_slab_thinner_than_a_voxel_passes_on_the_light_of_its_lit_face_alone(grid, face_bound):
    """A 2 cm slab whose back face alone a spot lights, both its faces inside one voxel of the
    32^3 and 64^3 grids: the voxels' two sides keep them apart, and the room's light is the
    path tracer's within 15 % (measured 1.057, 1.114; one side a voxel: 0.139, 0.073), the
    camera's face of the slab within 15 % (1.117, 1.121). At 128^3 the faces lie in two
    neighbouring voxels, one side each: the camera's face starts its cones away from the lit
    face behind it as a voxel's second side does (room 0.998, the camera's face 1.35, its near
    cells holding the lit face's light; 1.42 and 4.8x when its cones started on the face)."""
    image = render("thin_slab", grid=grid)
    expected = reference("thin_slab_gi")
    assert not reference("thin_slab_direct").any()  # every pixel's light is indirect
    assert luminance_ratio(image, expected) == pytest.approx(1.0, abs=0.15)
    assert image[THIN_SHEET_FRONT].mean() / expected[THIN_SHEET_FRONT].mean() == pytest.approx(1.0, abs=face_bound)


@pytest.mark.parametrize("grid, error_bound, luminance_bound", [(32, 0.31, 0.25), (64, 0.25, 0.20), (128, 0.19, 0.10)])
def test_a_double_sided_leaf_screen_lit_from_behind_reflects_from_both_sides(grid, error_bound, luminance_bound):
    """Foliage and cloth are one double-sided surface, here an alpha-masked screen of leaves
    inside one voxel, lit from behind by a spot: its voxels hold both of its sides, each lit and
    seen on its own. Against the path tracer (relMAE, luminance ratio): 0.298 / 1.223 at 32^3,
    0.225 / 1.149 at 64^3, 0.175 / 1.045 at 128^3 (one side a voxel: 0.324 / 0.810, 0.332 /
    0.866, 0.333 / 0.798; the coarse grids read bright, the gaps between the leaves narrower
    than a voxel)."""
    image = render("leaf_screen", grid=grid)
    expected = reference("leaf_screen_gi")
    assert not reference("leaf_screen_direct").any()  # the camera sees no directly lit surface
    assert rel_mae(image, expected) <= error_bound
    assert luminance_ratio(image, expected) == pytest.approx(1.0, abs=luminance_bound)
