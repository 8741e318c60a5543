"""tools/reference.py: how vct scenes become Mitsuba 3 scenes (no renders here but two small ones:
the texture orientation and a furnace).

Facts: a Lambertian material becomes `diffuse`; a material with a specular layer becomes the
tool's `vct_layered` BSDF (the scene format's glTF layers) with its base colour, roughness,
metalness and dielectric F0, per texel where textures give them; in a white furnace that BSDF
returns the light it receives (a white dielectric: 1, not the 1 + 0.086 of layers simply added;
a metal its Fresnel reflectance); a base-colour texture becomes a linear float bitmap (sRGB
decoded, times the factor) and the mesh keeps glTF's texture coordinates, which Mitsuba shows the
right way up; an emissive texture becomes the area emitter's radiance; alpha masks
become a `mask` BSDF with a per-texel 0/1 opacity (and `volpath`, whose shadow rays pass through
the holes), double-sided materials `twosided`; a part cut out everywhere is dropped. What the
tool cannot convert fails with one line naming the field and exit code 2.
"""
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import engine
from test_mesh_files import PAINTING, Gltf, png  # tests/ is on sys.path under pytest

mitsuba = pytest.importorskip("mitsuba")

ROOT = Path(__file__).resolve().parent.parent
TOOL = ROOT / "tools" / "reference.py"
CAMERA = {"position": [0.5, 0.5, 1.0], "look_at": [0.5, 0.5, 0.0], "vertical_fov_deg": 53.130102354, "width": 30, "height": 30}


@pytest.fixture(scope="module")
def reference():
    spec = importlib.util.spec_from_file_location("reference_tool", TOOL)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.use_mitsuba("scalar_rgb")
    return module


def write_scene(directory, objects, materials=None, lights=()):
    path = Path(directory) / "scene.json"
    path.write_text(json.dumps({"camera": CAMERA, "materials": materials or {}, "objects": objects, "lights": list(lights)}))
    return path


def quad(material="m"):
    return {"name": "Quad", "type": "quad", "material": material, "vertices": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]}


def convert(reference, scene_path, directory, max_depth=-1):
    scene = engine.load_scene(scene_path)
    return reference.scene_dict(scene, 4, max_depth, directory)


def shapes(converted):
    return [value for key, value in converted.items() if key.startswith("shape")]


def gltf_quad(directory, material, image=PAINTING):
    """A glb with one unit quad (image top-left at (0, 1, 0)) and one material using `image`."""
    g = Gltf()
    texture = g.texture(g.image(png(image)))
    spec = json.loads(json.dumps(material).replace('"TEXTURE"', str(texture)))
    g.add("meshes", {"primitives": [g.quad(g.add("materials", spec))]})
    g.add("nodes", {"name": "Model", "mesh": 0})
    g.doc["scenes"][0]["nodes"] = [0]
    g.write(Path(directory) / "model.glb")
    return write_scene(directory, [{"name": "Model", "type": "mesh", "file": "model.glb"}])


def bitmap_values(texture):
    assert texture["type"] == "bitmap" and texture["raw"] is True
    return np.array(texture["bitmap"], dtype=np.float64)


def test_lambertian_material_becomes_diffuse_with_the_albedo_and_world_space_geometry(reference, tmp_path):
    """A material with neither specular nor metalness is a `diffuse` BSDF of its albedo; the mesh is
    written in world space with its normals, and the integrator is `path`."""
    scene = write_scene(tmp_path, [dict(quad(), translation=[0, 0, -2])], {"m": {"albedo": [0.5, 0.25, 0.125]}})
    converted = convert(reference, scene, tmp_path)
    (shape,) = shapes(converted)
    assert shape["bsdf"] == {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.25, 0.125]}}
    vertices, names, triangles = reference.read_ply(shape["filename"])
    assert names == ["x", "y", "z", "nx", "ny", "nz"]
    np.testing.assert_allclose(vertices[:, 2], -2.0)
    np.testing.assert_allclose(vertices[:, 3:6], np.tile([0, 0, 1], (4, 1)))
    assert converted["integrator"] == {"type": "path", "max_depth": -1}


def test_a_specular_layer_becomes_the_layered_bsdf_with_the_materials_factors(reference, tmp_path):
    """A dielectric (specular 0.04) and a metal keep base colour, roughness (the renderer clamps
    it, and so does the BSDF), metalness and F0 as the renderer reads them."""
    scene = write_scene(tmp_path, [quad("plastic"), dict(quad("gold"), translation=[0, 0, -1])],
                        {"plastic": {"albedo": [0.1, 0.2, 0.6], "specular": 0.04, "roughness": 0.4},
                         "gold": {"albedo": [1.0, 0.78, 0.34], "metalness": 1.0, "roughness": 0.01}})
    plastic, gold = (shape["bsdf"] for shape in shapes(convert(reference, scene, tmp_path)))
    assert plastic == {"type": "vct_layered", "base_color": {"type": "rgb", "value": [0.1, 0.2, 0.6]},
                       "roughness": 0.4, "metalness": 0.0, "dielectric_f0": 0.04, "vertex_colors": False}
    assert gold == {"type": "vct_layered", "base_color": {"type": "rgb", "value": [1.0, 0.78, 0.34]},
                    "roughness": 0.01, "metalness": 1.0, "dielectric_f0": 0.0, "vertex_colors": False}
    assert reference.MIN_ROUGHNESS == 0.05


def test_metal_roughness_textures_become_per_texel_roughness_and_metalness(reference, tmp_path):
    """glTF's metallicRoughnessTexture: G x roughnessFactor and B x metallicFactor per texel."""
    image = np.zeros((2, 2, 3), np.uint8)
    image[..., 1] = [[255, 128], [0, 64]]
    image[..., 2] = [[255, 0], [255, 0]]
    scene = gltf_quad(tmp_path, {"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": "TEXTURE"},
                                                          "roughnessFactor": 0.5, "metallicFactor": 1.0}}, image)
    (shape,) = shapes(convert(reference, scene, tmp_path))
    bsdf = shape["bsdf"]
    assert bsdf["type"] == "vct_layered" and bsdf["dielectric_f0"] == 0.04
    np.testing.assert_allclose(bitmap_values(bsdf["roughness"]).reshape(2, 2), 0.5 * image[..., 1] / 255.0, atol=1e-6)
    np.testing.assert_allclose(bitmap_values(bsdf["metalness"]).reshape(2, 2), image[..., 2] / 255.0, atol=1e-6)


def furnace(directory, material):
    """A unit quad facing the camera (n.v = 1 at the centre) in a closed box whose walls emit 1
    and reflect nothing: every direction above the quad brings radiance 1."""
    h = 2.0
    walls = {"Floor": [[-h, -h, -h], [-h, -h, h], [h, -h, h], [h, -h, -h]], "Ceiling": [[-h, h, -h], [h, h, -h], [h, h, h], [-h, h, h]],
             "Left": [[-h, -h, -h], [-h, h, -h], [-h, h, h], [-h, -h, h]], "Right": [[h, -h, -h], [h, -h, h], [h, h, h], [h, h, -h]],
             "Back": [[-h, -h, -h], [h, -h, -h], [h, h, -h], [-h, h, -h]], "Front": [[-h, -h, h], [-h, h, h], [h, h, h], [h, -h, h]]}
    objects = [{"name": name, "type": "quad", "material": "glow", "vertices": v} for name, v in walls.items()]
    objects.append({"name": "Card", "type": "quad", "material": "m",
                    "vertices": [[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]]})
    path = Path(directory) / "furnace.json"
    path.write_text(json.dumps({"camera": {"position": [0, 0, 1.2], "look_at": [0, 0, 0], "vertical_fov_deg": 20,
                                           "width": 8, "height": 8},
                                "materials": {"glow": {"albedo": [0, 0, 0], "emission": [1, 1, 1]}, "m": material},
                                "objects": objects}))
    return path


@pytest.mark.parametrize("material, returned", [
    ({"albedo": [1, 1, 1], "specular": 0.04, "roughness": 0.1}, 1.0),
    ({"albedo": [1, 1, 1], "specular": 0.04, "roughness": 0.6}, 1.0),
    ({"albedo": [0.5, 0.5, 0.5], "metalness": 1.0, "roughness": 0.3}, 0.5),
], ids=["smooth-dielectric", "rough-dielectric", "metal"])
def test_in_a_white_furnace_the_layered_bsdf_returns_what_arrives(reference, tmp_path, material, returned):
    """Seen head-on (n.v = 1): the white dielectric's layers return 1 of the light between them,
    (1 - F0) 1 + F0 1, where layers simply added return 1 + F0 + (1 - F0) / 21 = 1.086; a metal of
    F0 = 0.5 its Fresnel reflectance 0.5."""
    scene = engine.load_scene(furnace(tmp_path, material))
    image, _, _, _ = reference.render(scene, spp=64, max_depth=-1, pass_spp=32)
    assert image.mean() == pytest.approx(returned, abs=0.02)


def test_base_colour_texture_is_a_linear_bitmap_and_texcoords_keep_the_gltf_convention(reference, tmp_path):
    """A glTF dielectric (specular 0.04) with a base-colour texture and factor (0.5, 1, 1): the
    base colour is the bitmap factor x sRGB-decoded texture, row 0 = the image's top, and the PLY
    holds the file's texture coordinates unchanged (u, v)."""
    scene = gltf_quad(tmp_path, {"pbrMetallicRoughness": {"baseColorTexture": {"index": "TEXTURE"},
                                                          "baseColorFactor": [0.5, 1.0, 1.0, 1.0], "metallicFactor": 0.0}})
    (shape,) = shapes(convert(reference, scene, tmp_path))
    diffuse = shape["bsdf"]["base_color"]
    expected = np.array([0.5, 1.0, 1.0]) * reference.srgb_to_linear(PAINTING / 255.0)
    np.testing.assert_allclose(bitmap_values(diffuse), expected, rtol=1e-6)
    assert diffuse["filter_type"] == "bilinear" and diffuse["wrap_mode"] == "repeat"
    vertices, names, _ = reference.read_ply(shape["filename"])
    assert names[-2:] == ["u", "v"]
    model = engine.load_scene(scene).drawables()[0][0].mesh
    np.testing.assert_allclose(vertices[:, -2:], model.texcoords)


def test_emissive_texture_is_the_area_emitters_radiance_and_shows_the_right_way_up(reference, tmp_path):
    """emissiveFactor x emissiveTexture becomes the area emitter's radiance bitmap (sRGB decoded);
    rendered straight on (30x30 pixels, emission only), each of PAINTING's 2x3 pixels appears in
    its place: the image's top-left at the quad's top-left, as the renderer draws it."""
    scene = gltf_quad(tmp_path, {"emissiveTexture": {"index": "TEXTURE"}, "emissiveFactor": [1.0, 0.5, 1.0],
                                 "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0}})
    converted = convert(reference, scene, tmp_path, max_depth=1)
    (shape,) = shapes(converted)
    radiance = np.array([1.0, 0.5, 1.0]) * reference.srgb_to_linear(PAINTING / 255.0)
    np.testing.assert_allclose(bitmap_values(shape["emitter"]["radiance"]), radiance, rtol=1e-6)
    image = np.array(mitsuba.render(mitsuba.load_dict(converted), spp=16))[..., :3]
    for row in range(3):  # near texel centres, where bilinear filtering mixes in 5 % of a neighbour on average
        for col in range(2):
            np.testing.assert_allclose(image[row * 10 + 5, col * 15 + 7], radiance[row, col], atol=0.1)


def test_alpha_mask_is_a_per_texel_opacity_inside_a_mask_bsdf_rendered_with_volpath(reference, tmp_path):
    """alphaMode MASK, alphaCutoff 0.5, baseColorFactor alpha 0.8, doubleSided, emissive: the
    opacity bitmap is 1 where texture alpha x 0.8 >= 0.5 and 0 elsewhere, read with nearest
    filtering, around a twosided BSDF; the emission is cut out the same way; the integrator is
    volpath."""
    image = np.zeros((2, 3, 4), np.uint8)
    image[..., :3] = 200
    image[..., 3] = [[255, 0, 160], [10, 255, 255]]  # x 0.8: 0.8, 0, 0.50, 0.03, 0.8, 0.8
    scene = gltf_quad(tmp_path, {"alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True, "emissiveFactor": [1, 1, 1],
                                 "pbrMetallicRoughness": {"baseColorTexture": {"index": "TEXTURE"},
                                                          "baseColorFactor": [1, 1, 1, 0.8], "metallicFactor": 0.0}},
                      image)
    converted = convert(reference, scene, tmp_path)
    (shape,) = shapes(converted)
    bsdf = shape["bsdf"]
    assert bsdf["type"] == "mask" and bsdf["bsdf"]["type"] == "twosided"
    keep = np.array([[1, 0, 1], [0, 1, 1]], float)
    np.testing.assert_array_equal(bitmap_values(bsdf["opacity"]).reshape(2, 3), keep)
    assert bsdf["opacity"]["filter_type"] == "nearest"
    np.testing.assert_allclose(bitmap_values(shape["emitter"]["radiance"]), np.repeat(keep[..., None], 3, axis=2))
    assert converted["integrator"]["type"] == "volpath"


def test_a_part_cut_out_everywhere_is_dropped_and_an_opaque_mask_needs_no_mask(reference, tmp_path):
    """MASK with a constant alpha below the cutoff draws nothing (no shape); at or above it, the
    plain BSDF (no `mask`, integrator `path`)."""
    for alpha, expected in ((0.2, 0), (0.6, 1)):
        scene = gltf_quad(tmp_path, {"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, alpha],
                                                                                   "metallicFactor": 0.0}})
        converted = convert(reference, scene, tmp_path)
        assert len(shapes(converted)) == expected
        assert converted["integrator"]["type"] == "path"
        if expected:
            assert shapes(converted)[0]["bsdf"]["type"] == "vct_layered"


def test_mitsuba_accepts_the_converted_scene_with_textures_masks_and_specular_layers(reference, tmp_path):
    """The dict of a scene with a textured, alpha-masked glTF part, a metal and a dielectric loads
    in Mitsuba (no render)."""
    image = np.zeros((4, 4, 4), np.uint8)
    image[..., 0] = 255
    image[..., 3] = 255
    image[::2, ::2, 3] = 0
    gltf_quad(tmp_path, {"alphaMode": "MASK", "doubleSided": True, "pbrMetallicRoughness": {
        "baseColorTexture": {"index": "TEXTURE"}, "metallicFactor": 0.5, "roughnessFactor": 0.3}}, image)
    scene = write_scene(tmp_path, [{"name": "Model", "type": "mesh", "file": "model.glb"},
                                   dict(quad("gold"), translation=[0, 0, -1]), dict(quad("plastic"), translation=[0, 0, -2])],
                        {"gold": {"albedo": [1.0, 0.78, 0.34], "metalness": 1.0, "roughness": 0.25},
                         "plastic": {"albedo": [0.1, 0.2, 0.6], "specular": 0.04, "roughness": 0.4}},
                        [{"type": "point", "position": [0, 1, 1], "intensity": [1, 1, 1]}])
    loaded = mitsuba.load_dict(convert(reference, scene, tmp_path))
    assert len(loaded.shapes()) == 3


def run_tool(*args):
    return subprocess.run([sys.executable, str(TOOL), *map(str, args)], capture_output=True, text=True, timeout=120)


def assert_one_line_error(result, *words):
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    for word in words:
        assert word in lines[0], lines[0]


def test_what_the_tool_cannot_convert_fails_with_one_line_naming_the_field(tmp_path):
    """A normal texture, a light with a range or without shadows, and bad arguments (--spp not a
    multiple of two passes, a non-.npy output) each fail with one line naming the field, exit
    code 2, and write nothing."""
    g = Gltf()
    texture = g.texture(g.image(png(PAINTING)))
    g.add("meshes", {"primitives": [g.quad(g.add("materials", {"name": "Bumpy", "normalTexture": {"index": texture}}))]})
    g.add("nodes", {"name": "Model", "mesh": 0})
    g.doc["scenes"][0]["nodes"] = [0]
    g.write(tmp_path / "model.glb")
    bumpy = write_scene(tmp_path, [{"name": "Model", "type": "mesh", "file": "model.glb"}])
    out = tmp_path / "out.npy"
    assert_one_line_error(run_tool(bumpy, out), "normal_texture", '"Bumpy"')
    for light, field in (({"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1], "range": 2.0}, "range"),
                         ({"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1], "cast_shadows": False}, "cast_shadows")):
        scene = write_scene(tmp_path, [quad()], {"m": {}}, [light])
        assert_one_line_error(run_tool(scene, out), field)
    scene = write_scene(tmp_path, [quad()], {"m": {}})
    assert_one_line_error(run_tool(scene, out, "--spp", 100), "--spp")
    assert_one_line_error(run_tool(scene, tmp_path / "out.exr"), "out", ".npy")
    assert not list(tmp_path.glob("out*"))


def test_a_render_writes_the_radiance_its_preview_and_its_metadata_together(tmp_path):
    """A small render (30x30, 8 samples in two halves) writes out.npy (linear float32, row 0 at
    the top), out.png and out.meta.json with the samples, the depth and the measured noise."""
    scene = write_scene(tmp_path, [quad()], {"m": {"albedo": [0.5, 0.5, 0.5]}},
                        [{"type": "point", "position": [0.5, 0.5, 0.5], "intensity": [1, 1, 1]}])
    out = tmp_path / "out.npy"
    result = run_tool(scene, out, "--spp", 8, "--pass-spp", 4, "--max-depth", 2)
    assert result.returncode == 0, result.stderr
    image = np.load(out)
    assert image.shape == (30, 30, 3) and image.dtype == np.float32 and image.mean() > 0.0
    meta = json.loads((tmp_path / "out.meta.json").read_text())
    assert meta["spp"] == 8 and meta["max_depth"] == 2 and meta["row0"] == "top"
    assert meta["convergence"]["halves_spp"] == 4
    assert (tmp_path / "out.png").stat().st_size > 0
