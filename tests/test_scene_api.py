"""Scenes built in code: engine.triangle_mesh, engine.check_scene, engine.from_trimesh, and the
README's examples of them.

Facts: the README's turntable and trimesh examples run as written (at a smaller size) and give
distinct, lit frames; a mesh given by positions and indices alone faces the way its winding
says; a scene built by hand is held to the limits of loaded scenes; from_trimesh keeps
trimesh's vertex and face colours (a red box renders red, not grey), its PBR and simple
materials with their textures, the texture coordinates flipped to glTF's convention, each node
where trimesh places it, sharp edges sharp and smooth surfaces smooth, and the camera trimesh
was given (creating none where it has none); it reads materials and colours as the glTF
loader reads the same scene exported to GLB; bad input is one VctError naming the argument or
the trimesh element.
"""
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image
from trimesh.transformations import rotation_matrix, scale_matrix, translation_matrix

import engine
from engine import SceneError, VctError

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
RED = [255, 0, 0, 255]


@pytest.fixture(scope="module")
def renderer():
    with engine.Renderer(64, 64, engine.RenderSettings(grid=32)) as r:
        yield r


def readme_example(introduction, replacements):
    """The code of the README's python block that follows the sentence `introduction`, each
    (old, new) of `replacements` made in it (each old text must be there once)."""
    text = README.read_text()
    assert text.count(introduction) == 1, f"the README no longer says {introduction!r}"
    code = re.search(r"```python\n(.*?)```", text[text.index(introduction):], re.S).group(1)
    for old, new in replacements:
        assert code.count(old) == 1, f"the README's example no longer holds {old!r}"
        code = code.replace(old, new)
    return code


def lit_scene(source, light_at=(1.0, 2.0, 2.0)):
    """from_trimesh of `source` with a point light of 5 W/sr added."""
    scene = engine.from_trimesh(source)
    scene.root.children.append(engine.Node("lamp", translation=np.array(light_at),
                                           light=engine.Light("point", intensity=np.full(3, 5.0))))
    return scene


def textured_card(material, uv=((0, 0), (1, 0), (1, 1), (0, 1))):
    """A unit square in the xy plane facing +z, with texture coordinates (trimesh's: v upwards)."""
    return trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], faces=[[0, 1, 2], [0, 2, 3]],
                           visual=trimesh.visual.TextureVisuals(uv=np.array(uv, float), material=material),
                           process=False)


# ---- the README's examples ------------------------------------------------------------------

def test_readme_turntable_renders_distinct_lit_frames(tmp_path, monkeypatch):
    """The README's turntable, run as written at 64x64, grid 32, 4 frames: a PNG per frame,
    none black, each seen from elsewhere and so each different."""
    code = readme_example("runs this turntable example", [
        ("frames = 36", "frames = 4"),
        ("engine.Renderer(320, 240, engine.RenderSettings(grid=64))", "engine.Renderer(64, 64, engine.RenderSettings(grid=32))"),
    ])
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md: turntable example", "exec"), {})
    frames = [np.asarray(Image.open(tmp_path / f"turntable_{i:03d}.png"), float) for i in range(4)]
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"turntable_{i:03d}.png" for i in range(4)]
    for i, frame in enumerate(frames):
        assert frame.shape == (64, 64, 3) and frame.mean() > 10, f"frame {i} is black"
        for j in range(i):
            assert np.abs(frame - frames[j]).mean() > 1.0, f"frames {j} and {i} are the same"


def test_readme_trimesh_example_renders_its_vertex_colours(tmp_path, monkeypatch):
    """The README's from_trimesh example at 64x64: lit by the sun it adds, the sphere shows
    the colours it was given (varied hues, not one grey)."""
    code = readme_example("runs this example too", [("engine.Renderer(256, 256)", "engine.Renderer(64, 64)")])
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md: trimesh example", "exec"), {})
    pixels = np.asarray(Image.open(tmp_path / "sphere.png"), float)
    lit = pixels[pixels.sum(axis=2) > 60]
    assert len(lit) > 200
    hues = lit / lit.sum(axis=1, keepdims=True)
    assert np.ptp(hues, axis=0).max() > 0.2


# ---- meshes from arrays and the limits of a scene built by hand ---------------------------------

def test_triangle_mesh_faces_the_way_its_winding_says():
    """Positions and indices alone: a counter-clockwise quad seen from +z gets unit normals
    along +z; given normals are scaled to unit length; a zero-area triangle is dropped."""
    corners = [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [5, 5, 5]]
    mesh = engine.triangle_mesh(corners, [[0, 1, 2], [0, 2, 3], [0, 0, 1]])
    assert mesh.indices.shape == (2, 3) and len(mesh.positions) == 4  # the unused vertex is gone
    np.testing.assert_allclose(mesh.normals, np.tile([0, 0, 1], (4, 1)), atol=1e-6)
    given = engine.triangle_mesh(corners[:4], [0, 1, 2, 0, 2, 3], normals=np.tile([0, 0, 3.0], (4, 1)),
                                 colors=np.tile([1.0, 0.5, 0.0, 1.0], (4, 1)))
    np.testing.assert_allclose(given.normals, np.tile([0, 0, 1], (4, 1)))
    np.testing.assert_allclose(given.colors, np.tile([1.0, 0.5, 0.0], (4, 1)))


def test_triangle_mesh_computes_smooth_normals_on_a_sphere():
    """A sphere's shared vertices get area-weighted normals along their radius."""
    sphere = trimesh.creation.icosphere(subdivisions=2)
    mesh = engine.triangle_mesh(sphere.vertices, sphere.faces)
    radial = mesh.positions / np.linalg.norm(mesh.positions, axis=1, keepdims=True)
    assert np.min(np.sum(mesh.normals * radial, axis=1)) > 0.99


@pytest.mark.parametrize("arguments, field, words", [
    (dict(positions=[[0, 0, 0], [1, 0, 0]], indices=[[0, 1, 2]]), "indices", "vertex numbers 0..1"),
    (dict(positions=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], indices=[[0, 1]]), "indices", "three per triangle"),
    (dict(positions=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], indices=[[0.0, 1.0, 2.0]]), "indices", "whole numbers"),
    (dict(positions=[[0, 0, 0], [1, 0, np.nan], [0, 1, 0]], indices=[[0, 1, 2]]), "positions", "element 1"),
    (dict(positions=[[0, 0], [1, 0], [0, 1]], indices=[[0, 1, 2]]), "positions", "shape (N, 3)"),
    (dict(positions=[[0, 0, 0], [1, 0, 0], [2, 0, 0]], indices=[[0, 1, 2]]), "indices", "no triangle has an area"),
    (dict(positions=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], indices=[[0, 1, 2]], normals=np.zeros((3, 3))), "normals",
     "must have a length"),
    (dict(positions=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], indices=[[0, 1, 2]], colors=np.full((3, 3), 2.0)), "colors",
     "within 0..1"),
    (dict(positions=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], indices=[[0, 1, 2]], texcoords=np.zeros((2, 2))), "texcoords",
     "has 2 elements, positions 3"),
])
def test_triangle_mesh_names_the_bad_argument(arguments, field, words):
    """Indices beyond the vertices, not in threes or not whole; positions not finite or not
    3D; no triangle with an area; zero normals; colours beyond 0..1; one row per vertex
    missing: each a VctError naming the argument."""
    with pytest.raises(VctError) as error:
        engine.triangle_mesh(**arguments)
    assert error.value.field == field and words in str(error.value)


def test_check_scene_holds_a_hand_built_scene_to_the_loaders_limits():
    """A scene built in code passes check_scene; a scale beyond 1e6, an albedo above 1, a
    texture on a mesh without texture coordinates and nodes nested 33 deep are each refused,
    naming the node and field."""
    ball = engine.Node("ball", mesh=engine.sphere_mesh(), material=engine.Material("red", albedo=np.array([0.8, 0.1, 0.1])))
    scene = engine.Scene("demo", engine.Node("root", children=[ball]),
                         engine.Camera(position=np.array([0.0, 0.0, 3.0]), look_at=np.zeros(3)))
    assert engine.check_scene(scene) is scene and scene.materials == {}
    ball.scale = np.full(3, 1e7)
    with pytest.raises(SceneError, match=r'scene "demo": node "ball".scale: .*scales by 1e\+07'):
        engine.check_scene(scene)
    ball.scale = np.ones(3)
    ball.material.albedo = np.array([1.5, 0.1, 0.1])
    with pytest.raises(SceneError, match=r'node "ball".material "red".albedo: albedo must be within 0..1'):
        engine.check_scene(scene)
    ball.material = engine.Material("tiles", base_color_texture=engine.Texture("tiles", np.zeros((2, 2, 3), np.uint8), True))
    with pytest.raises(SceneError, match=r'node "ball".mesh.texcoords: material "tiles" has a base_color_texture'):
        engine.check_scene(scene)
    ball.material = None
    chain = scene.root
    for level in range(33):
        chain.children = [engine.Node(f"level {level + 1}")]
        chain = chain.children[0]
    with pytest.raises(SceneError, match=r'node "level 33": nests more than 32 levels'):
        engine.check_scene(scene)
    with pytest.raises(VctError, match="must be an engine.Scene, got Node") as error:
        engine.check_scene(scene.root)
    assert error.value.field == "scene"


# ---- from_trimesh ------------------------------------------------------------------------

def test_vertex_coloured_trimesh_box_renders_red_not_grey(renderer):
    """A box whose vertices trimesh colours red, on a floor without colours, under a point
    light: its albedo is the vertex colour (1, 0, 0) and the light it reflects is red alone,
    while the floor stays the grey default."""
    box = trimesh.creation.box()
    box.visual.vertex_colors = np.tile(RED, (len(box.vertices), 1))
    source = trimesh.Scene(box)
    source.add_geometry(trimesh.creation.box(extents=[4, 0.1, 4]), node_name="floor",
                        transform=translation_matrix([0, -0.55, 0]))
    scene = lit_scene(source)
    albedo = renderer.render(scene, mode="albedo")
    box_pixels = np.all(np.isclose(albedo, [1, 0, 0], atol=1e-3), axis=2)
    floor_pixels = np.all(np.isclose(albedo, 0.8, atol=1e-3), axis=2)
    assert box_pixels.sum() > 100 and floor_pixels.sum() > 100
    assert np.all(box_pixels | floor_pixels | (albedo.max(axis=2) == 0))  # nothing else: the background
    direct = renderer.render(scene, mode="direct")[box_pixels]
    assert np.median(direct[:, 0]) > 0.05 and direct[:, 1:].max() == 0.0


def test_face_colours_give_each_face_its_colour():
    """Face colours: every face its own three vertices in its colour, with the face's normal."""
    box = trimesh.creation.box()
    box.visual.face_colors = np.array([RED if normal[0] > 0.5 else [0, 0, 255, 255] for normal in box.face_normals])
    mesh = engine.from_trimesh(box).drawables()[0][0].mesh
    assert len(mesh.positions) == 36
    corners = mesh.positions[mesh.indices]  # (12, 3, 3)
    facing_x = np.all(np.isclose(corners[:, :, 0], 0.5), axis=1)
    colors = mesh.colors[mesh.indices]
    np.testing.assert_allclose(colors[facing_x], np.tile([1, 0, 0], (2, 3, 1)))
    np.testing.assert_allclose(colors[~facing_x], np.tile([0, 0, 1], (10, 3, 1)))
    np.testing.assert_allclose(mesh.normals[mesh.indices][facing_x], np.tile([1, 0, 0], (2, 3, 1)), atol=1e-6)


def test_sharp_edges_stay_sharp_and_smooth_surfaces_smooth():
    """Without normals from trimesh: a box's faces (meeting at 90 degrees) keep their own
    vertices and flat normals; an icosphere's (a few degrees apart) share theirs, smooth along
    the radius; normals trimesh holds are used as they are."""
    box = engine.from_trimesh(trimesh.creation.box()).drawables()[0][0].mesh
    assert len(box.positions) == 24 and np.allclose(np.abs(box.normals).max(axis=1), 1.0)
    source = trimesh.creation.icosphere(subdivisions=2)
    sphere = engine.from_trimesh(source).drawables()[0][0].mesh
    assert len(sphere.positions) == len(source.vertices)
    radial = sphere.positions / np.linalg.norm(sphere.positions, axis=1, keepdims=True)
    assert np.min(np.sum(sphere.normals * radial, axis=1)) > 0.99
    held = trimesh.creation.box()
    held.vertex_normals = held.vertices / np.linalg.norm(held.vertices, axis=1, keepdims=True)
    corners = engine.from_trimesh(held).drawables()[0][0].mesh
    np.testing.assert_allclose(corners.normals, held.vertex_normals, atol=1e-6)


def test_pbr_material_factors_and_textures_survive():
    """A PBRMaterial's factors, its textures (pixels, colour space) and the texture
    coordinates (v flipped: trimesh's v grows upwards, glTF's downwards) reach the Material
    and Mesh; a normal texture brings tangents along +u."""
    image = Image.fromarray(np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]], np.uint8))
    material = trimesh.visual.material.PBRMaterial(
        name="painted", baseColorFactor=[0.2, 0.4, 0.6, 1.0], metallicFactor=0.3, roughnessFactor=0.7,
        emissiveFactor=[0.5, 0.25, 0.0], baseColorTexture=image, metallicRoughnessTexture=image.convert("L"),
        normalTexture=image, doubleSided=True, alphaMode="MASK", alphaCutoff=0.3)
    node = engine.from_trimesh(textured_card(material)).drawables()[0][0]
    m = node.material
    np.testing.assert_allclose(m.albedo, np.round(np.array([0.2, 0.4, 0.6]) * 255) / 255)
    assert (m.name, m.metalness, m.roughness, m.specular, m.double_sided) == ("painted", 0.3, 0.7, 0.04, True)
    assert (m.alpha_mode, m.alpha_cutoff) == ("MASK", 0.3)
    np.testing.assert_allclose(m.emission, [0.5, 0.25, 0.0])
    np.testing.assert_array_equal(m.base_color_texture.image, np.asarray(image))
    np.testing.assert_array_equal(m.metallic_roughness_texture.image[..., 0], np.asarray(image.convert("L")))
    assert m.base_color_texture.srgb and not m.metallic_roughness_texture.srgb and not m.normal_texture.srgb
    assert m.emissive_texture is None
    by_corner = {tuple(p): tuple(uv) for p, uv in zip(node.mesh.positions, node.mesh.texcoords)}
    assert by_corner[(0, 0, 0)] == (0, 1) and by_corner[(0, 1, 0)] == (0, 0)  # the image's top at the card's top
    np.testing.assert_allclose(node.mesh.tangents, np.tile([1, 0, 0, 1], (4, 1)), atol=1e-6)


def test_simple_material_is_read_as_an_mtl_material():
    """A SimpleMaterial: diffuse -> albedo, its image -> the base colour texture, glossiness
    (an MTL Ns) -> roughness (2 / (Ns + 2))^(1/4), a specular colour -> a 0.04 dielectric."""
    image = Image.new("RGB", (4, 4), (10, 20, 30))
    material = trimesh.visual.material.SimpleMaterial(image=image, diffuse=[128, 64, 32, 255], specular=[50, 50, 50],
                                                      glossiness=30.0)
    m = engine.from_trimesh(textured_card(material)).drawables()[0][0].material
    np.testing.assert_allclose(m.albedo, np.array([128, 64, 32]) / 255)
    assert m.roughness == pytest.approx((2 / 32) ** 0.25) and m.specular == 0.04 and m.metalness == 0.0
    assert m.alpha_mode == "OPAQUE" and m.base_color_texture.image[0, 0].tolist() == [10, 20, 30]


def test_materials_and_colours_match_the_same_scene_exported_to_glb(tmp_path):
    """from_trimesh reads a trimesh scene's PBR material, texture, texture coordinates and
    vertex colours as engine.load_scene reads that scene exported to GLB (whose COLOR_0 the
    glTF loader keeps: the file no longer renders grey)."""
    image = Image.fromarray(np.arange(48, dtype=np.uint8).reshape(4, 4, 3))
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[0.9, 0.5, 0.25, 1.0], metallicFactor=0.0,
                                                   roughnessFactor=0.5, emissiveFactor=[0.1, 0.2, 0.3],
                                                   baseColorTexture=image)
    card = textured_card(material)
    box = trimesh.creation.box()
    box.visual.vertex_colors = np.tile([255, 128, 0, 255], (len(box.vertices), 1))
    source = trimesh.Scene()
    source.add_geometry(card, node_name="card")
    source.add_geometry(box, node_name="box", transform=translation_matrix([3, 0, 0]))
    source.export(tmp_path / "scene.glb")
    ours = {node.name: node for node, _ in engine.from_trimesh(source).drawables()}
    loaded = {node.name: node for node, _ in engine.load_scene(tmp_path / "scene.glb").drawables()}
    a, b = ours["card"].material, loaded["card"].material
    for field in ("albedo", "alpha", "roughness", "metalness", "specular", "emission"):
        np.testing.assert_allclose(getattr(a, field), getattr(b, field), atol=1e-6, err_msg=field)
    assert (a.alpha_mode, a.double_sided) == (b.alpha_mode, b.double_sided)
    np.testing.assert_array_equal(a.base_color_texture.image, b.base_color_texture.image)
    uv_ours = {tuple(p): tuple(uv) for p, uv in zip(ours["card"].mesh.positions, ours["card"].mesh.texcoords)}
    uv_loaded = {tuple(p): tuple(uv) for p, uv in zip(loaded["card"].mesh.positions, loaded["card"].mesh.texcoords)}
    assert uv_ours == uv_loaded
    np.testing.assert_allclose(np.unique(ours["box"].mesh.colors, axis=0), [[1.0, 128 / 255, 0.0]], atol=1e-6)
    np.testing.assert_allclose(np.unique(loaded["box"].mesh.colors, axis=0), [[1.0, 128 / 255, 0.0]], atol=1e-6)


def test_nodes_land_where_trimesh_places_them():
    """Nested graph nodes (translated, turned, scaled unevenly) place their geometry where
    trimesh does: each world matrix and the scene's bounds are trimesh's; a geometry placed
    twice is one shared Mesh; an empty node is kept."""
    source = trimesh.Scene()
    box = trimesh.creation.box(extents=[1, 2, 3])
    arm = translation_matrix([1, 2, 3]) @ rotation_matrix(0.7, [1, 1, 0]) @ np.diag([2.0, 0.5, 1.5, 1.0])
    source.add_geometry(box, node_name="arm", geom_name="block", transform=arm)
    hand = translation_matrix([0, 1, 0]) @ rotation_matrix(-1.2, [0, 0, 1]) @ scale_matrix(0.5)
    source.graph.update(frame_to="hand", frame_from="arm", matrix=hand, geometry="block")
    source.graph.update(frame_to="marker", frame_from="hand", matrix=translation_matrix([0, 0, 4]))
    scene = engine.from_trimesh(source)
    worlds = {node.name: world for node, world in scene.root.walk()}
    for name in ("arm", "hand", "marker"):
        np.testing.assert_allclose(worlds[name], source.graph.get(name)[0], atol=1e-9, err_msg=name)
    np.testing.assert_allclose(np.array(scene.bounds()), source.bounds, atol=1e-6)
    arm_node, hand_node = scene.root.find("arm"), scene.root.find("hand")
    assert hand_node in arm_node.children and hand_node.mesh is arm_node.mesh


def test_the_camera_trimesh_was_given_is_kept_and_none_is_made():
    """A scene with a camera set renders from it (position, view along its -z, vertical field
    of view, resolution); a scene without one is framed, and trimesh is not made to create one."""
    source = trimesh.Scene(trimesh.creation.box())
    source.camera = trimesh.scene.Camera(resolution=(320, 200), fov=(60.0, 40.0))
    source.camera_transform = translation_matrix([0.5, 1.0, 5.0]) @ rotation_matrix(0.3, [0, 1, 0])
    camera = engine.from_trimesh(source).camera
    np.testing.assert_allclose(camera.position, [0.5, 1.0, 5.0])
    np.testing.assert_allclose(camera.look_at - camera.position, source.camera_transform[:3, :3] @ [0, 0, -1])
    assert (camera.vertical_fov_deg, camera.width, camera.height) == (40.0, 320, 200)
    bare = trimesh.Scene(trimesh.creation.box())
    framed = engine.from_trimesh(bare).camera
    assert framed.name == "framing" and not bare.has_camera


def test_bad_input_is_one_error_naming_what_is_wrong():
    """A sheared node, a vertex that is not finite, a point cloud, a texture without texture
    coordinates, an emission beyond the half-float range, a scene without triangles, nodes
    nested 33 deep and arguments of the wrong type are each a VctError naming the argument or
    the trimesh element."""
    sheared = trimesh.Scene()
    shear = np.eye(4)
    shear[0, 1] = 0.5
    sheared.add_geometry(trimesh.creation.box(), node_name="leaning", transform=shear)
    with pytest.raises(SceneError, match=r'trimesh scene "trimesh": node "leaning".matrix: is not a translation, '
                                         r"rotation and scale \(it shears"):
        engine.from_trimesh(sheared)
    broken = trimesh.creation.box()
    broken.vertices[3] = [np.nan, 0, 0]
    with pytest.raises(SceneError, match=r'geometry "geometry_0".vertices: element 3 is \[nan, 0.0, 0.0\]'):
        engine.from_trimesh(broken, name="broken")
    points = trimesh.Scene([trimesh.creation.box(), trimesh.PointCloud(np.zeros((3, 3)))])
    with pytest.raises(SceneError, match=r"is a PointCloud: only triangle meshes"):
        engine.from_trimesh(points)
    untextured = trimesh.creation.box()
    untextured.visual = trimesh.visual.TextureVisuals(
        material=trimesh.visual.material.PBRMaterial(name="tiles", baseColorTexture=Image.new("RGB", (2, 2))))
    with pytest.raises(SceneError, match=r'material "tiles" has textures but the mesh has no texture coordinates'):
        engine.from_trimesh(untextured)
    glowing = textured_card(trimesh.visual.material.PBRMaterial(emissiveFactor=[1e5, 0, 0]))
    with pytest.raises(SceneError, match=r'visual.material.emissiveFactor: emission must be within 0..65504'):
        engine.from_trimesh(glowing)
    with pytest.raises(SceneError, match=r'trimesh scene "trimesh": holds no triangles'):
        engine.from_trimesh(trimesh.Scene())
    deep, parent = trimesh.Scene(), "world"
    for level in range(1, 34):
        deep.graph.update(frame_to=f"level {level}", frame_from=parent, matrix=np.eye(4))
        parent = f"level {level}"
    with pytest.raises(SceneError, match=r'node "level 33": nests more than 32 levels deep'):
        engine.from_trimesh(deep)
    for arguments, field in (((np.zeros((3, 3)),), "scene_or_mesh"), ((trimesh.creation.box(), 3), "name")):
        with pytest.raises(VctError) as error:
            engine.from_trimesh(*arguments)
        assert error.value.field == field
