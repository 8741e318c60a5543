"""Files as other tools write them: Blender's all-quad OBJ, MeshLab's MTL, CAD tools' STL,
older exporters' GLB chunks, and glTF files that use what the spec allows (integers written
as 1.0, extensions' animation targets, textures whose image is an extension's, primitives
without positions, objects hidden by an animated scale of 0). A model file is a scene on its
own: framed, and lit by the studio sky where nothing lights it."""
import json
import struct
import warnings
from pathlib import Path

import numpy as np
import pytest

import engine
from engine.formats.mesh_building import polygon_triangles, quad_triangles
from engine.formats.mesh_files import load_mesh_file
from test_cli import vct  # tests/ is on sys.path under pytest
from test_mesh_files import Gltf, QUAD_POSITIONS

# A cube as Blender writes it without normals: six quads over eight shared corners.
CUBE_OBJ = """# Blender-style cube
mtllib cube.mtl
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
usemtl red
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
"""


def write_cube(directory, mtl="newmtl red\nKd 0.8 0.1 0.1\n"):
    (directory / "cube.mtl").write_text(mtl)
    path = directory / "cube.obj"
    path.write_text(CUBE_OBJ)
    return path


def loaded(path, name=None):
    """The nodes of a mesh file and the warnings its loading gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        nodes = load_mesh_file(path, name or path.name)
    return nodes, [str(w.message) for w in caught]


def assert_flat_faces(mesh, faces):
    """Every triangle's corners carry its own face normal: `faces` flat sides, no smoothing."""
    corners = mesh.positions[mesh.indices]
    face = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    np.testing.assert_allclose(mesh.normals[mesh.indices], np.repeat(face[:, None], 3, axis=1), atol=1e-6)
    assert len(np.unique(np.round(face, 5), axis=0)) == faces


def test_an_all_quad_obj_cube_is_twelve_triangles_with_six_flat_faces(tmp_path):
    """Blender writes quads: each becomes two triangles facing as the quad does (outwards), and
    a cube without normals is shaded flat, its 90-degree edges sharper than the crease angle."""
    (node,), messages = loaded(write_cube(tmp_path))
    mesh = node.mesh
    assert len(mesh.indices) == 12 and not messages
    corners = mesh.positions[mesh.indices]
    outward = np.einsum("ij,ij->i", np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), corners.mean(axis=1))
    assert np.all(outward > 0)
    assert_flat_faces(mesh, 6)
    np.testing.assert_allclose(node.material.albedo, [0.8, 0.1, 0.1])


def test_a_concave_polygon_is_cut_into_triangles_that_cover_exactly_its_area():
    """An L-shaped hexagon (area 3) and a quad whose reflex corner is 2 (a dart): the
    triangles lie inside, face as the polygon does, and their areas sum to the polygon's."""
    ell = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]], float)
    dart = np.array([[0, 0, 0], [2, 1, 0], [0.5, 1, 0], [0, 2, 0]], float)  # reflex at index 2
    for polygon, area, triangles in ((ell, 3.0, polygon_triangles(ell)), (dart, 1.25, quad_triangles(dart[None])[0]),
                                     (dart, 1.25, polygon_triangles(dart))):
        corners = polygon[triangles]
        z = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])[:, 2]
        assert np.all(z > 0) and 0.5 * z.sum() == pytest.approx(area)


def test_meshlab_mtl_tr_1_is_transparent_by_the_convention_and_says_so_naming_its_line(tmp_path):
    """MTL's Tr is 1 - d: `Tr 1.000000` makes the material fully transparent, which a warning
    names (file, material, line); `Tr 0` is opaque."""
    (node,), messages = loaded(write_cube(tmp_path, "newmtl red\nKd 0.8 0.1 0.1\nTr 1.000000\n"))
    assert node.material.alpha == 0.0
    assert len(messages) == 1 and 'newmtl "red": line 3 (Tr)' in messages[0] and "transparent" in messages[0]
    (node,), messages = loaded(write_cube(tmp_path, "newmtl red\nKd 0.8 0.1 0.1\nTr 0\n"))
    assert node.material.alpha == 1.0 and node.material.alpha_mode == "OPAQUE" and not messages


def test_an_stl_part_is_shaded_flat_at_its_edges_and_smooth_along_its_curves(tmp_path):
    """STL holds no normals: a box keeps its six flat faces, a cylinder's side (32 facets,
    11.25 degrees apart) is smooth, its caps flat."""
    import trimesh

    box = tmp_path / "box.stl"
    box.write_bytes(trimesh.creation.box((1, 2, 3)).export(file_type="stl"))
    (node,), _ = loaded(box)
    assert_flat_faces(node.mesh, 6)
    can = tmp_path / "can.stl"
    can.write_bytes(trimesh.creation.cylinder(0.5, 1.0, sections=32).export(file_type="stl"))
    (node,), _ = loaded(can)
    side = np.abs(node.mesh.normals[:, 2]) < 1e-6
    caps = np.abs(np.abs(node.mesh.normals[:, 2]) - 1) < 1e-6
    assert np.all(side | caps)  # no normal bends the cap's edge
    radial = node.mesh.positions[side, :2] / np.linalg.norm(node.mesh.positions[side, :2], axis=1, keepdims=True)
    np.testing.assert_allclose(node.mesh.normals[side, :2], radial, atol=1e-5)  # smooth: the radius's direction


def test_a_glb_whose_json_chunk_is_not_padded_is_read_with_a_warning(tmp_path):
    """Older trimesh wrote the JSON chunk unpadded; the BIN chunk follows it directly, which is
    unambiguous: the file loads, with one warning."""
    g = Gltf()
    g.doc["meshes"].append({"primitives": [g.quad()]})
    g.doc["nodes"].append({"name": "Quad", "mesh": 0})
    g.doc["scenes"][0]["nodes"] = [0]
    g.doc["buffers"][0]["byteLength"] = len(g.blob)
    text = json.dumps(g.doc).encode()
    text += b" " * (3 - len(text) % 4 if len(text) % 4 != 3 else 2)  # a length that is not a multiple of 4
    assert len(text) % 4
    blob = bytes(g.blob)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
    path = tmp_path / "unpadded.glb"
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)
    (node,), messages = loaded(path)
    def by_place(points):
        return points[np.argsort(points @ [1, 10, 0])]
    np.testing.assert_allclose(by_place(node.mesh.positions), by_place(QUAD_POSITIONS))
    assert len(messages) == 1 and "not padded" in messages[0]


def spec_corner_cases(tmp_path):
    """A glTF file using what the spec allows and vct once refused: its indices and enums written
    as floats (1.0), a KHR_animation_pointer channel in a file that uses the extension without
    requiring it, a texture with no source (its image an extension's), a primitive without
    POSITION, and a node hidden by an animated scale of 0 from t = 1 s to 2 s."""
    g = Gltf()
    material = g.add("materials", {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})
    g.doc["textures"].append({"extensions": {"EXT_texture_webp": {"source": 0}}})
    quad = g.quad(material)
    quad["indices"] = float(quad["indices"])
    for accessor in g.doc["accessors"]:
        accessor["componentType"] = float(accessor["componentType"])
    g.doc["meshes"].append({"primitives": [quad, {"attributes": {"NORMAL": quad["attributes"]["NORMAL"]}}]})
    g.doc["nodes"].append({"name": "Quad", "mesh": 0.0})
    g.doc["scenes"][0]["nodes"] = [0]
    times = g.accessor(np.array([0.0, 1.0, 2.0], np.float32))
    scales = g.accessor(np.array([[1, 1, 1], [0, 0, 0], [0, 0, 0]], np.float32))
    weights = g.accessor(np.array([0.0, 1.0, 1.0], np.float32))
    g.doc["animations"] = [{"name": "hide", "samplers": [{"input": times, "output": scales, "interpolation": "STEP"},
                                                         {"input": times, "output": weights}],
                            "channels": [{"sampler": 0, "target": {"node": 0, "path": "scale"}},
                                         {"sampler": 1, "target": {"path": "pointer", "extensions": {
                                             "KHR_animation_pointer": {"pointer": "/materials/0/alphaCutoff"}}}}]}]
    g.doc["extensionsUsed"] = ["KHR_animation_pointer", "EXT_texture_webp"]
    return g.write(tmp_path / "corner_cases.gltf")


def test_valid_gltf_corner_cases_load_and_what_is_not_drawn_is_named_once(tmp_path):
    path = spec_corner_cases(tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = engine.load_scene(path)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 3, messages  # the extensions left out, the texture without its image, the primitive
    assert "KHR_animation_pointer" in messages[0] and "textures[0]" in messages[1] and "without POSITION" in messages[2]
    (node,) = [node for node, _ in scene.root.walk() if node.mesh is not None]
    assert node.material.base_color_texture is None
    with engine.Renderer(32, 32) as r:
        seen = r.render(scene.pose_at(0.5), mode="albedo").max()
        hidden = r.render(scene.pose_at(1.5), mode="albedo").max()
    assert seen > 0.5 and hidden == 0.0


def test_a_model_file_alone_renders_under_the_studio_sky_or_black_when_asked(tmp_path):
    """`vct render cube.obj`: framed, lit by the studio sky with one line saying so, the top face
    (L = rho 0.87, rho = 0.8 red) brighter than the sides (0.6); `--environment none` keeps
    it black with the warning that says why."""
    path = write_cube(tmp_path)
    result = vct("render", str(path), "--out", str(tmp_path / "cube.png"), "--hdr", str(tmp_path / "cube.npy"),
                 "--mode", "direct", "--width", "64", "--height", "64")
    assert result.returncode == 0 and result.stderr.count("\n") == 1 and "studio sky" in result.stderr, result.stderr
    image = np.load(tmp_path / "cube.npy")
    assert image[32, 32, 0] == pytest.approx(0.8 * 0.6, rel=0.1)  # the front face: L = rho (0.6 + 0.4 d.y)
    result = vct("render", str(path), "--out", str(tmp_path / "black.png"), "--hdr", str(tmp_path / "black.npy"),
                 "--mode", "direct", "--width", "64", "--height", "64", "--environment", "none")
    assert result.returncode == 0 and "no light" in result.stderr
    assert np.load(tmp_path / "black.npy").max() == 0.0


def test_the_conformance_tool_renders_each_model_and_names_what_it_refused(tmp_path):
    """tools/conformance.py over a folder laid out as the Khronos Sample Assets: a model that
    renders (its image on the contact sheet), one refused with vct's error line in the table."""
    import subprocess
    import sys

    from PIL import Image

    models = tmp_path / "Models"
    (models / "Quad" / "glTF").mkdir(parents=True)
    g = Gltf()
    g.doc["meshes"].append({"primitives": [g.quad()]})
    g.doc["nodes"].append({"name": "Quad", "mesh": 0})
    g.doc["scenes"][0]["nodes"] = [0]
    g.write(models / "Quad" / "glTF" / "Quad.gltf")
    (models / "Broken" / "glTF-Binary").mkdir(parents=True)
    (models / "Broken" / "glTF-Binary" / "Broken.glb").write_bytes(b"glTF" + bytes(8))
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "tools/conformance.py", str(models), "--out", str(out), "--size", "48",
                           "--mode", "direct"], cwd=Path(__file__).resolve().parent.parent, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    rows = {row["model"]: row for row in json.loads((out / "results.json").read_text())}
    assert rows["Quad"]["result"] == "rendered" and any("studio sky" in w for w in rows["Quad"]["warnings"])
    assert rows["Broken"]["result"] == "refused" and "Broken.glb" in rows["Broken"]["detail"]
    assert Image.open(out / "contact_sheet.png").size == (2 * 48, 48 + 14)
    assert "1 rendered, 1 refused" in (out / "results.md").read_text()
