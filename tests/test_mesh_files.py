"""Mesh files (engine.formats.mesh_files): glTF/GLB and OBJ+MTL keep their structure, materials and textures.

Facts: a glTF built here loads into its node hierarchy (names, TRS and matrix transforms), one node
per primitive with that primitive's material; materials follow the documented glTF mapping;
textures hold the image as stored (row 0 at the top), sRGB for colour and linear for data, one
shared object per image used the same way; texture coordinates keep glTF's convention; normals
and tangents come from the file, and are made (flat normals, tangents with the glTF handedness)
only where it has none. An OBJ with two material groups gives two nodes with their MTL
materials and v flipped to glTF's convention. Sponza loads whole. Bad files fail with one line
naming the scene, the object, the mesh file and the element.
"""
import copy
import io
import json
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from engine import SceneError, load_scene
from engine.core.limits import MAX_IMAGE_SIDE as MAX_TEXTURE_SIZE
from engine.core.transforms import compose, transform_points
from engine.formats.mesh_files import load_mesh_file
from test_cli import assert_one_line_error, vct  # tests/ is on sys.path under pytest

ROOT = Path(__file__).resolve().parent.parent
SPONZA = [ROOT / "scenes" / "sponza" / "sponza_512.glb", ROOT.parent / "shared" / "assets" / "sponza" / "sponza_512.glb"]

# A 2x3 image (2 wide, 3 tall) whose every pixel differs, so any flip or transpose shows.
PAINTING = np.array([[[255, 0, 0], [0, 255, 0]],
                     [[0, 0, 255], [255, 255, 0]],
                     [[0, 255, 255], [255, 0, 255]]], np.uint8)

# A unit quad in the xy plane facing +z; its texture coordinates put the image's top-left
# corner (glTF texcoord (0, 0)) at the quad's top-left corner (0, 1, 0).
QUAD_POSITIONS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
QUAD_TEXCOORDS = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
QUAD_INDICES = np.array([0, 1, 2, 0, 2, 3], np.uint32)


def png(pixels):
    out = io.BytesIO()
    Image.fromarray(pixels).save(out, format="PNG")
    return out.getvalue()


class Gltf:
    """A glTF document built by a test: arrays in one binary buffer, images embedded or by URI."""

    TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}
    COMPONENTS = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "u1"}

    def __init__(self):
        self.doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "materials": [], "textures": [], "images": [], "accessors": [], "bufferViews": [],
                    "buffers": [{"byteLength": 0}]}
        self.blob = bytearray()

    def add(self, key, spec):
        self.doc[key].append(spec)
        return len(self.doc[key]) - 1

    def view(self, data):
        self.blob += b"\0" * (-len(self.blob) % 4)
        index = self.add("bufferViews", {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)})
        self.blob += data
        return index

    def accessor(self, array, component=5126):
        array = np.asarray(array)
        width = 1 if array.ndim == 1 else array.shape[1]
        data = array.astype(self.COMPONENTS[component]).tobytes()
        return self.add("accessors", {"bufferView": self.view(data), "componentType": component, "count": len(array),
                                      "type": self.TYPES[width]})

    def image(self, data):
        return self.add("images", {"bufferView": self.view(data), "mimeType": "image/png"})

    def texture(self, image):
        return self.add("textures", {"source": image})

    def quad(self, material=None, normals=True, texcoords=QUAD_TEXCOORDS, tangents=None):
        attributes = {"POSITION": self.accessor(QUAD_POSITIONS)}
        if normals:
            attributes["NORMAL"] = self.accessor(np.tile([0, 0, 1], (4, 1)))
        if texcoords is not None:
            attributes["TEXCOORD_0"] = self.accessor(texcoords)
        if tangents is not None:
            attributes["TANGENT"] = self.accessor(tangents)
        primitive = {"attributes": attributes, "indices": self.accessor(QUAD_INDICES, 5125)}
        if material is not None:
            primitive["material"] = material
        return primitive

    def write(self, path):
        path = Path(path)
        self.doc["buffers"][0]["byteLength"] = len(self.blob)
        if path.suffix == ".glb":
            text = json.dumps(self.doc).encode()
            text += b" " * (-len(text) % 4)
            blob = bytes(self.blob) + b"\0" * (-len(self.blob) % 4)
            chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
            path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)
        else:
            self.doc["buffers"][0]["uri"] = path.stem + ".bin"
            path.with_suffix(".bin").write_bytes(bytes(self.blob))
            path.write_text(json.dumps(self.doc))
        return path


def two_material_gltf():
    """Root (T (1,2,3), 90 degrees about y, scale 2) -> Pair (a mesh of two quads: Painted, Plain)
    and Matrix Node (a matrix, one quad: Also Painted). Painted samples PAINTING as base colour
    and as metal-roughness; Also Painted samples a second glTF image with the same PNG bytes."""
    g = Gltf()
    painting = g.texture(g.image(png(PAINTING)))
    painting_again = g.texture(g.image(png(PAINTING)))
    painted = g.add("materials", {
        "name": "Painted", "doubleSided": True, "alphaMode": "MASK", "alphaCutoff": 0.3,
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1.0, 1.0, 0.8], "baseColorTexture": {"index": painting},
                                 "metallicRoughnessTexture": {"index": painting}},
        "emissiveFactor": [1.0, 0.5, 0.0], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}})
    plain = g.add("materials", {"name": "Plain", "alphaMode": "BLEND", "pbrMetallicRoughness": {
        "baseColorFactor": [0.2, 0.4, 0.6, 1.0], "metallicFactor": 0.25, "roughnessFactor": 0.5}})
    also = g.add("materials", {"name": "Also Painted", "pbrMetallicRoughness": {"baseColorTexture": {"index": painting_again}}})
    pair = g.add("meshes", {"name": "Quads", "primitives": [g.quad(painted), g.quad(plain)]})
    single = g.add("meshes", {"primitives": [g.quad(also)]})
    s = math.sqrt(0.5)
    g.add("nodes", {"name": "Root", "translation": [1, 2, 3], "rotation": [0, s, 0, s], "scale": [2, 2, 2], "children": [1, 2]})
    g.add("nodes", {"name": "Pair", "mesh": pair})
    matrix = np.diag([3.0, 3.0, 3.0, 1.0])
    matrix[:3, 3] = [0, 5, 0]
    g.add("nodes", {"name": "Matrix Node", "mesh": single, "matrix": matrix.T.reshape(-1).tolist()})  # column-major
    g.doc["scenes"][0]["nodes"] = [0]
    return g


def parts(nodes):
    """{name: node} of every node with a mesh."""
    return {node.name: node for root in nodes for node, _ in root.walk() if node.mesh is not None}


# ---- glTF structure ------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_gltf_hierarchy_keeps_node_names_and_gives_each_primitive_its_own_node_and_material(tmp_path, suffix):
    """glTF nodes become nodes with their names; a mesh of two primitives becomes two child
    nodes, each with its primitive's material; one primitive stays on its node (.glb and .gltf+.bin)."""
    (root,) = load_mesh_file(two_material_gltf().write(tmp_path / f"model{suffix}"), "model")
    assert root.name == "Root" and root.mesh is None
    pair, matrix_node = root.children
    assert (pair.name, matrix_node.name) == ("Pair", "Matrix Node")
    assert pair.mesh is None
    assert [(c.name, c.material.name) for c in pair.children] == [("Pair: Painted", "Painted"), ("Pair: Plain", "Plain")]
    assert matrix_node.mesh is not None and matrix_node.material.name == "Also Painted"


def test_gltf_translation_rotation_scale_and_matrix_give_the_files_world_transforms(tmp_path):
    """Root's TRS (quaternion 90 degrees about y) and the child's column-major matrix compose
    to the world matrices the glTF spec defines."""
    (root,) = load_mesh_file(two_material_gltf().write(tmp_path / "model.glb"), "model")
    worlds = {node.name: world for node, world in root.walk()}
    root_world = compose([1, 2, 3], [0, 90, 0], [2, 2, 2])
    np.testing.assert_allclose(worlds["Root"], root_world, atol=1e-12)
    child = np.diag([3.0, 3.0, 3.0, 1.0])
    child[:3, 3] = [0, 5, 0]
    np.testing.assert_allclose(worlds["Matrix Node"], root_world @ child, atol=1e-12)
    # +x turns towards -z under 90 degrees about +y: the quad's (1, 0, 0) corner lands at (1, 2, 1).
    np.testing.assert_allclose(transform_points(worlds["Pair: Painted"], [[1, 0, 0]])[0], [1, 2, 1], atol=1e-12)


def test_gltf_materials_follow_the_documented_metallic_roughness_mapping(tmp_path):
    """Base colour factor -> albedo and alpha, factors -> metalness/roughness (glTF's default
    metallic 1), specular 0.04, emission = emissiveFactor x emissiveStrength, alpha mode and
    cutoff (0.5 for BLEND), doubleSided."""
    found = parts(load_mesh_file(two_material_gltf().write(tmp_path / "model.glb"), "model"))
    painted, plain, also = (found[name].material for name in ("Pair: Painted", "Pair: Plain", "Matrix Node"))
    np.testing.assert_allclose(painted.albedo, [0.5, 1.0, 1.0])
    assert painted.alpha == pytest.approx(0.8)
    assert (painted.alpha_mode, painted.alpha_cutoff, painted.double_sided) == ("MASK", pytest.approx(0.3), True)
    np.testing.assert_allclose(painted.emission, [4.0, 2.0, 0.0])
    assert (painted.metalness, painted.roughness) == (1.0, 1.0)
    np.testing.assert_allclose(plain.albedo, [0.2, 0.4, 0.6])
    assert (plain.metalness, plain.roughness) == (0.25, 0.5)
    assert (plain.alpha_mode, plain.alpha_cutoff, plain.double_sided) == ("BLEND", 0.5, False)
    assert plain.textures() == [] and also.alpha_mode == "OPAQUE"
    assert {painted.specular, plain.specular, also.specular} == {0.04}


def test_gltf_texture_holds_the_image_top_row_first_and_is_shared_by_materials_using_it_the_same_way(tmp_path):
    """The base-colour texture is the PNG's pixels, row 0 = the image's top, sRGB; the same
    image as metal-roughness is a linear texture sharing the pixels; a second glTF image with
    the same bytes used as base colour is the very same Texture object."""
    found = parts(load_mesh_file(two_material_gltf().write(tmp_path / "model.glb"), "model"))
    painted, also = found["Pair: Painted"].material, found["Matrix Node"].material
    color = painted.base_color_texture
    np.testing.assert_array_equal(color.image, PAINTING)
    assert color.srgb and (color.wrap_s, color.wrap_t) == ("REPEAT", "REPEAT")
    assert color.image.dtype == np.uint8 and not color.image.flags.writeable
    data = painted.metallic_roughness_texture
    assert not data.srgb and data is not color and data.image is color.image
    assert also.base_color_texture is color
    assert "images[0]" in color.name


def test_a_copied_material_shares_its_textures(tmp_path):
    """copy.deepcopy of a material (the inspector's "make unique") keeps the same Texture
    objects, so the copy uploads nothing new."""
    painted = parts(load_mesh_file(two_material_gltf().write(tmp_path / "model.glb"), "model"))["Pair: Painted"].material
    copied = copy.deepcopy(painted)
    assert copied is not painted and copied.base_color_texture is painted.base_color_texture


def test_gltf_texture_coordinates_keep_the_gltf_convention(tmp_path):
    """TEXCOORD_0 is kept as stored: (0, 0) is the image's top-left, here at the quad's top-left
    corner (0, 1, 0); float32 (V, 2)."""
    mesh = parts(load_mesh_file(two_material_gltf().write(tmp_path / "model.glb"), "model"))["Pair: Painted"].mesh
    assert mesh.texcoords.dtype == np.float32 and mesh.texcoords.shape == (4, 2)
    np.testing.assert_array_equal(mesh.texcoords, QUAD_TEXCOORDS)
    top_left = np.flatnonzero((mesh.texcoords == [0, 0]).all(axis=1))[0]
    np.testing.assert_array_equal(mesh.positions[top_left], [0, 1, 0])


def test_gltf_sampler_wrap_modes_reach_the_texture(tmp_path):
    """A sampler's wrapS/wrapT (GL enums) become the texture's wrap modes by GL name."""
    g = Gltf()
    g.doc["samplers"] = [{"wrapS": 33071, "wrapT": 33648}]
    texture = g.add("textures", {"source": g.image(png(PAINTING)), "sampler": 0})
    material = g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": texture}}})
    g.doc["scenes"][0]["nodes"] = [g.add("nodes", {"mesh": g.add("meshes", {"primitives": [g.quad(material)]})})]
    (node,) = load_mesh_file(g.write(tmp_path / "model.glb"), "model")
    texture = node.material.base_color_texture
    assert (texture.wrap_s, texture.wrap_t) == ("CLAMP_TO_EDGE", "MIRRORED_REPEAT")


def single_quad(tmp_path, normal_map=False, **quad):
    g = Gltf()
    material = None
    if normal_map:
        material = g.add("materials", {"normalTexture": {"index": g.texture(g.image(png(PAINTING))), "scale": 0.5}})
    g.doc["scenes"][0]["nodes"] = [g.add("nodes", {"mesh": g.add("meshes", {"primitives": [g.quad(material, **quad)]})})]
    (node,) = load_mesh_file(g.write(tmp_path / "quad.glb"), "quad.glb")
    return node


def test_gltf_normals_come_from_the_file(tmp_path):
    """NORMAL is kept as stored (a quad's +z), not recomputed; vertices stay shared."""
    mesh = single_quad(tmp_path).mesh
    np.testing.assert_array_equal(mesh.normals, np.tile([0, 0, 1], (4, 1)))
    assert len(mesh.positions) == 4


def test_gltf_without_normals_gets_flat_normals(tmp_path):
    """Without NORMAL each triangle gets its own corners with its face normal (the glTF rule)."""
    mesh = single_quad(tmp_path, normals=False).mesh
    assert len(mesh.positions) == 6 and len(mesh.texcoords) == 6
    np.testing.assert_allclose(mesh.normals, np.tile([0, 0, 1], (6, 1)))


def test_normal_texture_without_tangents_gets_tangents_along_u_with_the_gltf_handedness(tmp_path):
    """With a normal texture and no TANGENT: tangent = direction of +u (+x here), w = +1 as the
    image's top is at +y = cross(n, t); mirroring u flips the tangent and w = -1."""
    node = single_quad(tmp_path, normal_map=True)
    assert node.material.normal_scale == 0.5 and not node.material.normal_texture.srgb
    np.testing.assert_allclose(node.mesh.tangents, np.tile([1, 0, 0, 1], (4, 1)), atol=1e-6)
    mirrored = single_quad(tmp_path, normal_map=True, texcoords=np.column_stack([1 - QUAD_TEXCOORDS[:, 0], QUAD_TEXCOORDS[:, 1]]))
    np.testing.assert_allclose(mirrored.mesh.tangents, np.tile([-1, 0, 0, -1], (4, 1)), atol=1e-6)


def test_tangents_from_the_file_are_kept(tmp_path):
    """TANGENT in the file is used as stored."""
    stored = np.tile([0, 1, 0, -1], (4, 1)).astype(np.float32)
    np.testing.assert_array_equal(single_quad(tmp_path, normal_map=True, tangents=stored).mesh.tangents, stored)


def test_mesh_data_from_files_is_read_only(tmp_path):
    """Loaded meshes' arrays refuse in-place writes (edits replace arrays)."""
    mesh = single_quad(tmp_path, normal_map=True).mesh
    for array in (mesh.positions, mesh.normals, mesh.indices, mesh.texcoords, mesh.tangents):
        assert not array.flags.writeable
    with pytest.raises(ValueError):
        mesh.positions[0, 0] = 1.0


# ---- OBJ + MTL -----------------------------------------------------------------------------

OBJ = """mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl Brick
f 1/1/1 2/2/1 3/3/1
usemtl Glow
f 1/1/1 3/3/1 4/4/1
"""

MTL = """newmtl Brick
Kd 0.5 0.25 1.0
Ks 0.5 0.5 0.5
Ns 98
map_Kd brick.png

newmtl Glow
Ke 2 1 0.5
map_Kd brick.png
map_d mask.png
d 0.9
"""

MASK = np.array([[0, 255], [128, 64], [255, 0]], np.uint8)  # grey, 2x3 like PAINTING


def write_obj(directory, obj=OBJ, mtl=MTL):
    directory = Path(directory)
    (directory / "two.obj").write_text(obj)
    (directory / "two.mtl").write_text(mtl)
    (directory / "brick.png").write_bytes(png(PAINTING))
    (directory / "mask.png").write_bytes(png(MASK))
    return directory / "two.obj"


def test_obj_with_two_material_groups_gives_two_nodes_with_their_mtl_materials(tmp_path):
    """One node per usemtl group, named after its material: Kd x map_Kd, Ns 98 -> roughness
    (2/100)^(1/4), Ks -> specular 0.04; Ke, d and map_d -> emission, alpha 0.9 (BLEND) and the
    base colour's alpha channel."""
    brick, glow = load_mesh_file(write_obj(tmp_path), "two.obj")
    assert (brick.name, glow.name) == ("Brick", "Glow")
    assert (brick.material.name, glow.material.name) == ("Brick", "Glow")
    assert len(brick.mesh.indices) == 1 and len(glow.mesh.indices) == 1
    b, g = brick.material, glow.material
    np.testing.assert_allclose(b.albedo, [0.5, 0.25, 1.0])
    assert b.roughness == pytest.approx((2 / 100) ** 0.25) and b.specular == 0.04
    assert (b.alpha, b.alpha_mode) == (1.0, "OPAQUE")
    np.testing.assert_array_equal(b.base_color_texture.image, PAINTING)
    assert b.base_color_texture.srgb
    np.testing.assert_allclose(g.albedo, [1, 1, 1])  # Kd defaults to 1 under a map_Kd
    np.testing.assert_allclose(g.emission, [2, 1, 0.5])
    assert (g.alpha, g.alpha_mode, g.alpha_cutoff, g.specular, g.roughness) == (0.9, "BLEND", 0.5, 0.0, 1.0)
    np.testing.assert_array_equal(g.base_color_texture.image, np.dstack([PAINTING, MASK]))


def test_obj_texture_coordinates_are_flipped_to_the_gltf_convention_and_normals_kept(tmp_path):
    """OBJ's vt (v up) becomes (u, 1 - v): here vt = (x, y), so texcoords = (x, 1 - y); vn kept."""
    for node in load_mesh_file(write_obj(tmp_path), "two.obj"):
        mesh = node.mesh
        np.testing.assert_allclose(mesh.texcoords, np.column_stack([mesh.positions[:, 0], 1 - mesh.positions[:, 1]]))
        np.testing.assert_array_equal(mesh.normals, np.tile([0, 0, 1], (len(mesh.positions), 1)))


def test_obj_without_normals_gets_smooth_normals(tmp_path):
    """No vn: vertex normals are computed (the quad's +z)."""
    obj = OBJ.replace("vn 0 0 1\n", "").replace("/1 ", " ").replace("/1\n", "\n")
    assert "vn" not in obj and "/1/" not in obj
    for node in load_mesh_file(write_obj(tmp_path, obj=obj), "two.obj"):
        np.testing.assert_allclose(node.mesh.normals, np.tile([0, 0, 1], (len(node.mesh.positions), 1)), atol=1e-6)


# ---- Sponza --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def sponza():
    path = next((p for p in SPONZA if p.is_file()), None)
    if path is None:
        pytest.skip("Sponza is neither in scenes/sponza/ nor in ../shared/assets/sponza/")
    return load_mesh_file(path, path.name)


def test_sponza_loads_25_parts_with_25_materials_and_24_shared_textures(sponza):
    """All 262,267 triangles but the 412 of zero area, 25 materials, 24 base-colour textures
    (one object each), the masked leaves/chains/plants with RGBA textures, normals and
    texcoords from the file."""
    found = parts(sponza)
    materials = {id(n.material): n.material for n in found.values()}
    textures = {id(t): t for m in materials.values() for t in m.textures()}
    assert len(found) == 25 and len(materials) == 25 and len(textures) == 24
    assert sum(len(n.mesh.indices) for n in found.values()) == 262267 - 412
    masked = sorted(m.name for m in materials.values() if m.alpha_mode == "MASK")
    assert masked == ["Material__57", "chain", "leaf"]
    for m in materials.values():
        assert m.specular == 0.04
        if m.alpha_mode == "MASK":
            assert m.base_color_texture.image.shape[2] == 4 and m.double_sided
    assert all(n.mesh.texcoords is not None for n in found.values() if n.material.textures())


def test_sponza_scene_file_uses_the_files_materials():
    """scenes/sponza.json's mesh object has no material: its 25 parts keep theirs."""
    if not SPONZA[0].is_file():
        pytest.skip("scenes/sponza/sponza_512.glb is not present")
    scene = load_scene(ROOT / "scenes" / "sponza.json")
    assert len(scene.drawables()) == 25 and len(scene.textures()) == 24
    assert {light.type for _, light in scene.lights()} == {"directional", "point"}


# ---- bad input -----------------------------------------------------------------------------

def textured_quad():
    g = Gltf()
    material = g.add("materials", {"name": "Painted", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": g.texture(g.image(png(PAINTING)))}}})
    g.doc["scenes"][0]["nodes"] = [g.add("nodes", {"mesh": g.add("meshes", {"primitives": [g.quad(material)]})})]
    return g


def _missing_image(g):
    g.doc["images"][0] = {"uri": "textures/missing.png"}


def _corrupt_image(g):
    g.doc["images"][0] = {"bufferView": g.view(b"this is not a PNG"), "mimeType": "image/png"}


def _huge_image(g):
    g.doc["images"][0] = {"bufferView": g.view(png(np.zeros((1, MAX_TEXTURE_SIZE + 1, 3), np.uint8))), "mimeType": "image/png"}


def _no_texcoords(g):
    del g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]


def _mode(mode):
    def change(g):
        g.doc["meshes"][0]["primitives"][0]["mode"] = mode
    return change


def _required(g):
    g.doc["extensionsRequired"] = ["KHR_draco_mesh_compression"]


TEXTURE = "materials[0].pbrMetallicRoughness.baseColorTexture"
BAD_GLTF = {
    "missing-texture": (_missing_image, TEXTURE, "textures/missing.png", "file not found"),
    "corrupt-texture": (_corrupt_image, TEXTURE, "cannot decode image"),
    "texture-too-large": (_huge_image, TEXTURE, f"{MAX_TEXTURE_SIZE + 1}x1 pixels", str(MAX_TEXTURE_SIZE)),
    "texture-without-texcoords": (_no_texcoords, "meshes[0].primitives[0]", '"Painted"', "TEXCOORD_0"),
    "points": (_mode(0), "meshes[0].primitives[0].mode", "POINTS"),
    "lines": (_mode(1), "meshes[0].primitives[0].mode", "LINES"),
    "unsupported-required-extension": (_required, "extensionsRequired", "KHR_draco_mesh_compression"),
}


def write_model_scene(directory, model, material=None):
    """A scene with one mesh object "Model" (optionally with a scene material) loading `model`."""
    spec = {"name": "Model", "type": "mesh", "file": model}
    if material:
        spec["material"] = material
    scene = {"camera": {"position": [0, 0.5, 3], "look_at": [0.5, 0.5, 0]},
             "materials": {"white": {"albedo": [0.7, 0.7, 0.7]}}, "objects": [spec],
             "lights": [{"type": "directional", "direction": [0, 0, -1], "irradiance": [1, 1, 1]}]}
    path = Path(directory) / "scene.json"
    path.write_text(json.dumps(scene))
    return path


@pytest.mark.parametrize("case", BAD_GLTF, ids=str)
def test_bad_gltf_raises_one_line_naming_scene_object_file_and_element(tmp_path, case):
    """Each broken glTF fails at load with `scene.json: objects[0] "Model".file: model.glb:
    <element>: <problem>`."""
    change, *mentions = BAD_GLTF[case]
    g = textured_quad()
    change(g)
    g.write(tmp_path / "model.glb")
    scene = write_model_scene(tmp_path, "model.glb")
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f'{scene}: objects[0] "Model".file: model.glb: '), message
    for mention in mentions:
        assert mention in message, message


def test_bad_texture_is_no_error_where_a_scene_material_overrides_the_files(tmp_path):
    """With `material` on the object the file's materials (and their textures) are not read:
    every part gets the scene's material."""
    g = textured_quad()
    _missing_image(g)
    g.write(tmp_path / "model.glb")
    scene = load_scene(write_model_scene(tmp_path, "model.glb", material="white"))
    (node, _), = scene.drawables()
    assert node.material is scene.materials["white"]


@pytest.mark.parametrize("mtl, obj, mentions", [
    (MTL.replace("mask.png", "gone.png"), OBJ, ["two.mtl: line 10 (map_d)", '"gone.png"', "file not found"]),
    (MTL, OBJ.replace("two.mtl", "none.mtl"), ['two.obj: mtllib "none.mtl"', "file not found"]),
    (MTL, OBJ.replace("usemtl Glow", "usemtl Gold"), ['two.obj: usemtl "Gold"', "no material of that name"]),
    (MTL.replace("Kd 0.5 0.25 1.0", "Kd 1.5 0.25 1.0"), OBJ, ["two.mtl: line 2 (Kd)", "0..1"]),
    (MTL.replace("map_d mask.png", "map_d -s 2 2 mask.png"), OBJ, ["two.mtl: line 10 (map_d)", "-s"]),
], ids=["missing-texture", "missing-mtllib", "unknown-usemtl", "albedo-above-one", "texture-option"])
def test_bad_obj_or_mtl_raises_one_line_naming_the_file_and_line(tmp_path, mtl, obj, mentions):
    """A broken OBJ/MTL fails with the object's field, the file and the statement at fault."""
    write_obj(tmp_path, obj=obj, mtl=mtl)
    scene = write_model_scene(tmp_path, "two.obj")
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f'{scene}: objects[0] "Model".file: ')
    for mention in mentions:
        assert mention in message, message


def test_vct_render_of_a_scene_with_a_broken_texture_exits_2_with_one_line_and_writes_nothing(tmp_path):
    """The CLI reports a bad texture like any bad input: exit 2, one line, no output files."""
    g = textured_quad()
    _corrupt_image(g)
    g.write(tmp_path / "model.glb")
    out = tmp_path / "out"
    out.mkdir()
    result = vct("render", write_model_scene(tmp_path, "model.glb"), "--out", out / "x.png", "--hdr", out / "x.exr")
    assert_one_line_error(result, 'objects[0] "Model".file: model.glb: ' + TEXTURE, "cannot decode image")
    assert list(out.iterdir()) == []


def test_mesh_object_keeps_the_files_parts_as_child_nodes_with_their_materials(tmp_path):
    """A mesh object without `material` holds the file's parts as child nodes with the file's
    materials; with `material` the scene's material replaces them all, and an OBJ file's
    material groups, which no longer matter, load as one mesh."""
    write_obj(tmp_path)
    scene = load_scene(write_model_scene(tmp_path, "two.obj"))
    model = scene.root.find("Model")
    assert model.mesh is None
    assert [(c.name, c.material.name) for c in model.children] == [("Brick", "Brick"), ("Glow", "Glow")]
    scene = load_scene(write_model_scene(tmp_path, "two.obj", material="white"))
    model = scene.root.find("Model")
    assert model.children == [] and model.material is scene.materials["white"]
    assert len(model.mesh.indices) == sum(len(c.mesh.indices) for c in load_scene(write_model_scene(tmp_path, "two.obj")).root.find("Model").children)
