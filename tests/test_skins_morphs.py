"""Skins and morph targets played: a skinned mesh follows its joints (linear blend skinning,
glTF 2.0 3.7.3.3) and a morphed one its weights (3.7.2.2), posed on the GPU so that the
G-buffer, the shadows and the voxels all see the pose, checked against poses computed here
from the spec; a frame re-voxelizes only what moved and matches a fresh render of the pose."""
import math

import numpy as np
import pytest

import engine
from engine.core.transforms import quaternion_rotation
from test_mesh_files import Gltf

# A strip two metres tall in the xy plane facing +z: rows of vertices at y = 0, 1, 2.
STRIP = np.array([[-0.25, 0, 0], [0.25, 0, 0], [-0.25, 1, 0], [0.25, 1, 0], [-0.25, 2, 0], [0.25, 2, 0]], np.float32)
STRIP_INDICES = np.array([0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4], np.uint32)
# Two joints: the root at the origin moves rows 0 and half of row 1, the elbow at y = 1 the rest.
STRIP_JOINTS = np.array([[0, 1, 0, 0]] * 6, np.uint8)
STRIP_WEIGHTS = np.array([[1, 0, 0, 0]] * 2 + [[0.5, 0.5, 0, 0]] * 2 + [[0, 1, 0, 0]] * 2, np.float32)
BEND = [0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)]  # 90 degrees about +z


def skinned_strip(path, sets=1):
    """The strip skinned to a root joint and an elbow joint (its child, at y = 1), its inverse
    bind matrices the inverse of the joints' rest world matrices; an animation bends the
    elbow by 90 degrees about +z over one second and holds it for one more. The strip's own
    node is placed 5 m away: glTF says a skinned mesh ignores it. With `sets` 2 each joint's
    influence comes in a set of its own (JOINTS_0/WEIGHTS_0, JOINTS_1/WEIGHTS_1)."""
    g = Gltf()
    attributes = {"POSITION": g.accessor(STRIP), "NORMAL": g.accessor(np.tile([0, 0, 1], (6, 1)))}
    if sets == 1:
        attributes.update(JOINTS_0=g.accessor(STRIP_JOINTS, 5121), WEIGHTS_0=g.accessor(STRIP_WEIGHTS))
    else:
        for joint in range(2):
            joints = np.zeros((6, 4), np.uint8)
            joints[:, 0] = joint
            weights = np.zeros((6, 4), np.float32)
            weights[:, 0] = STRIP_WEIGHTS[:, joint]
            attributes.update({f"JOINTS_{joint}": g.accessor(joints, 5121), f"WEIGHTS_{joint}": g.accessor(weights)})
    primitive = {"attributes": attributes, "indices": g.accessor(STRIP_INDICES, 5125)}
    g.doc["meshes"].append({"primitives": [primitive]})
    inverse_bind = np.stack([np.eye(4), np.linalg.inv(_translation([0, 1, 0]))]).transpose(0, 2, 1).reshape(2, 16)
    g.doc["nodes"] = [{"name": "Strip", "mesh": 0, "skin": 0, "translation": [5, 0, 0]},
                      {"name": "Root", "children": [2]}, {"name": "Elbow", "translation": [0, 1, 0]}]
    g.doc["scenes"][0]["nodes"] = [0, 1]
    g.doc["skins"] = [{"joints": [1, 2], "inverseBindMatrices": g.add("accessors", {
        "bufferView": g.view(inverse_bind.astype("<f4").tobytes()), "componentType": 5126, "count": 2, "type": "MAT4"})}]
    times = g.accessor(np.array([0.0, 1.0, 2.0], np.float32))  # held for a second: pose_at loops over 2 s
    rotations = g.accessor(np.array([[0, 0, 0, 1], BEND, BEND], np.float32))
    g.doc["animations"] = [{"name": "bend", "samplers": [{"input": times, "output": rotations}],
                            "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}]}]
    return g.write(path)


def _translation(t):
    m = np.eye(4)
    m[:3, 3] = t
    return m


def expected_skin(elbow_quaternion):
    """The strip's vertices posed by the spec: v' = sum_i w_i world(joint_i) inverse_bind_i v."""
    elbow = _translation([0, 1, 0])
    elbow[:3, :3] = quaternion_rotation(elbow_quaternion)
    matrices = [np.eye(4), elbow @ np.linalg.inv(_translation([0, 1, 0]))]
    points = np.hstack([STRIP, np.ones((6, 1))])
    posed = sum(STRIP_WEIGHTS[:, [i]] * (points @ matrices[i].T) for i in range(2))
    return posed[:, :3]


def seen_points_lie_on(positions, vertices, indices, tolerance):
    """Whether every pixel's world point lies on one of the triangles (within `tolerance`), and
    the share of pixels that see any."""
    seen = positions[np.isfinite(positions[..., 0])]
    triangles = vertices[indices.reshape(-1, 3)]
    distances = np.full(len(seen), np.inf)
    for a, b, c in triangles:
        normal = np.cross(b - a, c - a)
        normal /= np.linalg.norm(normal)
        height = (seen - a) @ normal
        flat = seen - height[:, None] * normal
        inside = np.ones(len(seen), bool)
        for p, q in ((a, b), (b, c), (c, a)):
            inside &= np.cross(q - p, flat - p) @ normal >= -tolerance
        distances = np.where(inside, np.minimum(distances, np.abs(height)), distances)
    return bool(np.all(distances < tolerance)), len(seen)


def camera_on(scene):
    scene.camera = engine.Camera(np.array([0.0, 1.0, 6.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 1.0, 0.0]), 40.0, 96, 96)
    scene.environment = engine.scene.model.Environment(radiance=np.ones(3))
    return scene


@pytest.mark.parametrize("sets", [1, 2])
def test_a_skinned_mesh_follows_its_joints_as_the_spec_poses_it(tmp_path, sets):
    """At rest the strip stands where its joints hold it (not 5 m away at its node); bent by
    the animation every point the camera sees lies on the strip posed by the spec, and the
    top of the strip, rotated 90 degrees about the elbow, points along -x; the same with its
    influences in two sets of four."""
    scene = camera_on(engine.load_scene(skinned_strip(tmp_path / "strip.gltf", sets)))
    with engine.Renderer(96, 96) as r:
        for t, quaternion in ((0.0, [0, 0, 0, 1]), (1.0, BEND)):
            r.render(scene.pose_at(t), mode="albedo")
            on_strip, seen = seen_points_lie_on(r.positions(), expected_skin(quaternion), STRIP_INDICES, 2e-3)
            assert on_strip and seen > 200, t
        positions = r.positions()
    assert np.nanmin(positions[..., 0]) < -0.6  # the bent half reaches past the elbow along -x
    assert np.nanmax(positions[..., 1]) < 1.3   # and nothing stands up to y = 2 any more


def with_floor_and_sun(scene):
    """A floor under the strip and a sun at an angle: the strip's shadow falls on the floor."""
    floor = engine.Node("Floor", mesh=engine.quad_mesh([[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]]),
                        material=engine.Material("floor"))
    sun = engine.Node("Sun", light=engine.Light("directional", np.full(3, 2.0), direction=np.array([0.5, -1.0, -0.5])))
    scene.root.children += [floor, sun]
    return scene


def test_a_bent_pose_is_voxelized_and_shadowed_as_a_fresh_render_of_it(tmp_path):
    """Posing re-voxelizes what moved and redraws its shadow: the voxels and the image after
    the bend equal those of a new renderer given the bent scene, bit for bit."""
    path = skinned_strip(tmp_path / "strip.gltf")
    scene = with_floor_and_sun(camera_on(engine.load_scene(path)))
    with engine.Renderer(64, 64) as r:
        r.render(scene.pose_at(0.0), grid=32, bounces=1)
        image = r.render(scene.pose_at(0.6), grid=32, bounces=1)
        voxels = [r.voxels(name) for name in ("albedo", "normal")]
    fresh_scene = with_floor_and_sun(camera_on(engine.load_scene(path))).pose_at(0.6)
    with engine.Renderer(64, 64) as fresh:
        expected = fresh.render(fresh_scene, grid=32, bounces=1)
        assert all(np.array_equal(v, fresh.voxels(name)) for v, name in zip(voxels, ("albedo", "normal")))
    assert np.array_equal(image, expected)


def morphed_quad(path, default_weights=(0.25,), animated=True):
    """A unit quad whose one morph target lifts its top edge by 1 m and tilts its normals,
    its default weights `default_weights`, an animation taking the weight 0 -> 1 over 1 s
    (held for 1 s more)."""
    g = Gltf()
    quad = g.quad()
    lift = np.array([[0, 0, 0], [0, 0, 0], [0, 1, 0], [0, 1, 0]], np.float32)
    quad["targets"] = [{"POSITION": g.accessor(lift)}]
    g.doc["meshes"].append({"primitives": [quad], "weights": list(default_weights)})
    g.doc["nodes"].append({"name": "Quad", "mesh": 0})
    g.doc["scenes"][0]["nodes"] = [0]
    if animated:
        times, weights = g.accessor(np.array([0.0, 1.0, 2.0], np.float32)), g.accessor(np.array([0.0, 1.0, 1.0], np.float32))
        g.doc["animations"] = [{"name": "lift", "samplers": [{"input": times, "output": weights}],
                                "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]
    return g.write(path)


@pytest.mark.parametrize("t, weight", [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0)])
def test_morph_targets_move_the_vertices_by_their_weights(tmp_path, t, weight):
    """p = p0 + w dp: the quad's top edge at y = 1 + w."""
    scene = engine.load_scene(morphed_quad(tmp_path / "quad.gltf")).pose_at(t)
    scene.camera = engine.Camera(np.array([0.5, 1.0, 4.0]), np.array([0.5, 1.0, 0.0]), np.array([0.0, 1.0, 0.0]), 50.0, 96, 96)
    scene.environment = engine.scene.model.Environment(radiance=np.ones(3))
    with engine.Renderer(96, 96) as r:
        r.render(scene, mode="albedo")
        positions = r.positions()
    top = np.nanmax(positions[..., 1])
    assert top == pytest.approx(1.0 + weight, abs=0.05)
    quad = np.array([[0, 0, 0], [1, 0, 0], [1, 1 + weight, 0], [0, 1 + weight, 0]], float)
    assert seen_points_lie_on(positions, quad, np.array([0, 1, 2, 0, 2, 3]), 2e-3)[0]


def test_a_mesh_without_node_weights_takes_its_default_weights(tmp_path):
    scene = engine.load_scene(morphed_quad(tmp_path / "quad.gltf", default_weights=(0.25,), animated=False))
    (node,) = [node for node, _ in scene.drawables()]
    np.testing.assert_allclose(node.mesh.target_weights, [0.25])
    scene.camera = engine.Camera(np.array([0.5, 1.0, 4.0]), np.array([0.5, 1.0, 0.0]), np.array([0.0, 1.0, 0.0]), 50.0, 96, 96)
    with engine.Renderer(96, 96) as r:
        r.render(scene, mode="albedo")
        assert np.nanmax(r.positions()[..., 1]) == pytest.approx(1.25, abs=0.05)


def test_the_pose_is_computed_once_per_change_and_not_in_a_still_frame(tmp_path):
    """A frame where nothing moved poses nothing; one where a joint moved poses its draw."""
    scene = camera_on(engine.load_scene(skinned_strip(tmp_path / "strip.gltf")))
    with engine.Renderer(32, 32) as r:
        r.render(scene.pose_at(0.0), mode="direct")
        r.render(scene, mode="direct")
        assert "pose" not in r.passes_ran
        r.render(scene.pose_at(0.5), mode="direct")
        assert "pose" in r.passes_ran
