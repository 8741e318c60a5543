"""Drawing the scene from the GPU: meshes shared by nodes held once, every raster pass a fixed
number of multi-draws culled on the GPU, and a frame that finds what changed from the scene's
edits, not by walking it: a frame's host work does not grow with the objects that did not move."""
import numpy as np
import pytest

import engine
from engine.core import transforms
from engine.core.constants import DRAW_TEST_FRUSTUM, MATERIAL_TEXTURE_ARRAYS
from engine.gpu.context import create_headless_context
from engine.gpu.scene_buffers import SceneBuffers, texture_groups
from engine.gpu.shaders import ProgramLibrary
from engine.passes.cull import CullPass, DrawList, view_records
from engine.scene.model import Camera, Light, Material, Node, Scene, Texture, box_mesh, quad_mesh
from engine.scene.table import SceneTable


def field_of_boxes(count, materials=4):
    """`count` boxes (a square number) on a ground, all sharing one mesh, under a sun."""
    side = int(round(count ** 0.5))
    mesh = box_mesh()
    palette = [Material(f"m{k}", albedo=np.array([0.2 + 0.15 * k, 0.5, 0.4])) for k in range(materials)]
    ground = Node("ground", mesh=quad_mesh([[-4, 0, -4], [-4, 0, 4], [4, 0, 4], [4, 0, -4]]), material=Material("ground"))
    boxes = [Node(f"box {i}", translation=np.array([(i % side + 0.5) * 8 / side - 4, 0.2, (i // side + 0.5) * 8 / side - 4]),
                  scale=np.full(3, 3.0 / side), mesh=mesh, material=palette[i % materials]) for i in range(count)]
    sun = Node("sun", light=Light("directional", np.full(3, 3.0), direction=np.array([0.3, -1.0, 0.2])))
    camera = Camera(np.array([-6.0, 4.0, -6.0]), np.zeros(3), np.array([0.0, 1.0, 0.0]), 50.0, 64, 64)
    return Scene("boxes", Node("root", children=[ground, *boxes, sun]), camera)


def test_nodes_that_share_a_mesh_hold_one_copy_of_it_on_the_gpu():
    """64 boxes of one mesh: the pool holds the ground's and the box's vertices, once each."""
    scene = field_of_boxes(64)
    with engine.Renderer(64, 64) as r:
        r.render(scene, mode="direct")
        assert r.held_meshes == (2, 4 + 24)


def test_a_frame_issues_as_many_multi_draws_for_thousands_of_objects_as_for_a_few():
    """The G-buffer and the shadow maps draw a bucket (program variant and face culling) with
    one multi-draw-indirect each, whatever the objects: 16 and 1024 boxes take the same number
    of draw calls in a frame, direct and with the voxels."""
    calls = {}
    for count in (16, 1024):
        scene = field_of_boxes(count)
        with engine.Renderer(64, 64) as r:
            for mode in ("direct", "gi"):
                r.render(scene, mode=mode, grid=32)
                calls[count, mode] = r.draw_calls
    assert calls[16, "direct"] == calls[1024, "direct"] and calls[16, "gi"] == calls[1024, "gi"]
    assert calls[16, "direct"] <= 4  # a bucket of the G-buffer, the shadow maps' opaque bucket


def test_the_camera_draws_the_clusters_in_its_frustum_and_no_others():
    """The culling pass keeps a draw's cluster for the camera exactly where its world box
    meets the view frustum (all eight corners beyond one clip plane: culled), as the host
    computes it for the same boxes."""
    scene = field_of_boxes(256)
    scene.camera = Camera(np.array([0.0, 1.0, -5.0]), np.array([2.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), 30.0, 64, 64)
    table = SceneTable()
    table.sync(scene)
    ctx = create_headless_context()
    with ctx:
        buffers, cull = SceneBuffers(ctx), CullPass(ctx, ProgramLibrary(ctx))
        draw_list = DrawList(ctx, lambda flags: np.zeros(len(flags), int), 1)
        buffers.sync(table)
        view_projection = engine.frame.camera.frame_camera(scene.camera, (64, 64), table.bounds).view_projection
        views = view_records(1)
        views["view_projection"][0] = np.asarray(view_projection, "f4").T.ravel()
        draw_list.build(buffers)
        views["items"][0] = (0, draw_list.item_count, DRAW_TEST_FRUSTUM, 0)
        cull.run(draw_list, buffers, views)
        commands = np.frombuffer(draw_list.commands.read(), "u4")[:5 * draw_list.command_count].reshape(-1, 5)
        expected = 0
        for draw in range(table.draw_count):
            entry = buffers.draw_entries[draw]
            for cluster in buffers.pool.clusters[entry.first_cluster:entry.first_cluster + entry.cluster_count]:
                corners = transforms.box_corners(cluster["lo"][:3], cluster["hi"][:3]) @ table.draw_world[draw][:3, :3].T
                corners += table.draw_world[draw][:3, 3]
                expected += not transforms.outside_frustum(corners[None], view_projection)[0]
        for resource in (draw_list, cull, buffers):
            resource.release()
    ctx.release()
    assert 0 < commands[:, 1].sum() == expected < table.draw_count


def test_a_static_frame_reads_no_node_of_the_scene():
    """Once drawn, a frame where only the camera moved finds that nothing else changed from the
    scene's edit log: it walks no node, computes no node's matrix and touches no draw's record;
    it fits the sun's shadow cascades to the camera again (redrawing none, as they still hold its
    view) and touches no voxel."""
    scene = field_of_boxes(256)
    with engine.Renderer(64, 64) as r:
        r.render(scene, mode="gi", grid=32)
        walk, local = Node.walk, Node.local_matrix
        try:
            Node.walk = Node.local_matrix = lambda self, *a: pytest.fail("a static frame read the scene's nodes")
            scene.camera.position = scene.camera.position + [0.1, 0.0, 0.0]
            r.render(scene, mode="gi", grid=32)
        finally:
            Node.walk, Node.local_matrix = walk, local
        assert r.passes_ran == ["shadow", "gbuffer", "lighting", "cone_trace"]  # the sun's cascades follow the camera
        assert r.shadow.drawn_tiles == []  # and still hold its view: none is drawn again


@pytest.mark.parametrize("edit, passes", [
    (lambda s: s.root.find("box 5").translation.__iadd__([0.3, 0.0, 0.0]), {"shadow", "gbuffer", "voxelize"}),
    (lambda s: s.root.find("sun").light.direction.__setitem__(slice(None), [0.1, -1.0, 0.4]), {"shadow", "lighting"}),
    (lambda s: s.root.find("box 5").material.albedo.__setitem__(0, 0.9), {"gbuffer", "voxelize"}),
])
def test_an_edit_written_into_an_array_of_the_scene_is_drawn(edit, passes):
    """A node's transform, a light's direction and a material's albedo written in place
    (`node.translation += step`, `light.direction[:] = d`, `material.albedo[0] = a`) are
    edits the next frame sees, as assigning them is: the frame equals a fresh render."""
    scene = field_of_boxes(16)
    with engine.Renderer(64, 64) as r:
        r.render(scene, grid=32, bounces=1)
        edit(scene)
        image = r.render(scene, grid=32, bounces=1)
        assert passes <= set(r.passes_ran)
    with engine.Renderer(64, 64) as fresh:
        assert np.array_equal(fresh.render(scene, grid=32, bounces=1), image)


def test_textures_of_more_kinds_than_arrays_share_the_nearest_size_of_their_kind():
    """Textures go into a texture array per size, colour encoding and wrap modes; where a scene
    has more kinds than arrays, the kinds with the fewest textures join the nearest size of
    their encoding and wrapping (resampled), never another encoding."""
    textures = [Texture(f"t{k}", np.zeros((8 * (k + 1), 16, 4), np.uint8), srgb=k % 2 == 0) for k in range(2 * MATERIAL_TEXTURE_ARRAYS)]
    groups = texture_groups(textures, max_layers=2048)
    assert len(groups) <= MATERIAL_TEXTURE_ARRAYS
    assert sorted(id(t) for _, members in groups for t in members) == sorted(id(t) for t in textures)
    for (size, srgb, *_), members in groups:  # an array keeps one of its textures' sizes
        assert all(t.srgb == srgb for t in members) and any(t.image.shape[1::-1] == size for t in members)


def test_a_mirroring_node_shows_its_surfaces_as_their_mirror_image_does():
    """A box is its own mirror image: boxes scaled by -1 along x (a negative determinant, the
    winding reversed) light as the unmirrored boxes, their normals still facing out, and
    voxelize alike up to the order the rasterizer meets their triangles (under 2%)."""
    images = {}
    for sign in (1, -1):
        scene = field_of_boxes(16)
        for node in scene.root.children[1:17]:
            node.scale[0] *= sign
        with engine.Renderer(64, 64) as r:
            images[sign] = {mode: r.render(scene, mode=mode, grid=32) for mode in ("direct", "gi")}
    for mode in ("direct", "gi"):
        a, b = images[1][mode], images[-1][mode]
        assert a.mean() > 0.05
        assert np.abs(a - b).sum() / a.sum() < {"direct": 1e-3, "gi": 0.02}[mode], mode


def test_a_node_flattened_to_zero_thickness_shows_its_flat_faces():
    """A scale of 0 along y (as animations hide or squash things) leaves a box's top face: it
    renders lit from above with its normal up, as a quad at its height does, and nothing fails
    for the matrix having no inverse. With the voxels the box's bottom face, facing down in the
    same cells, adds its few percent."""
    flattened, quads = field_of_boxes(16), field_of_boxes(16)
    top = quad_mesh([[-0.5, 0.5, -0.5], [-0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.5, 0.5, -0.5]])
    for flat, quad in zip(flattened.root.children[1:17], quads.root.children[1:17]):
        flat.scale[1] = 0.0
        quad.mesh, quad.scale[1] = top, 0.0
    with engine.Renderer(64, 64) as r:
        for mode in ("direct", "gi"):
            a, b = r.render(flattened, mode=mode, grid=32), r.render(quads, mode=mode, grid=32)
            assert np.abs(a - b).sum() / b.sum() < {"direct": 1e-3, "gi": 0.05}[mode], mode
