"""Writes scenes/references/gltf_room.glb, gltf_spheres.glb (build_spheres: glTF dielectrics and
metals at three roughnesses, for scenes/references/gltf_spheres.json) and scenes/animated_room.glb
(the room with the node animations of `animate`). gltf_room.glb is a room
as Blender's exporter writes glTF, rendered as
the scene itself (`vct render scenes/references/gltf_room.glb`) with its own camera and lights:

- a room 4 m wide and deep and 2.5 m high (floor at y = 0, centred on the origin): a floor
  with a base-colour texture of 8x8 oak-coloured checks (FLOOR) tiled 4 x 4 times by
  KHR_texture_transform (scale 4, 4), roughness 0.5; warm white walls (0.75, 0.72, 0.66) but for
  a terracotta back wall (0.65, 0.30, 0.20), and a white ceiling (0.8), all glTF dielectrics of
  roughness 0.9;
- a box 0.6 x 0.9 x 0.6 m (left, turned 25 degrees about y) whose COLOR_0 runs from red at the
  floor to blue at its top, base colour white, roughness 0.8;
- three spheres of radius 0.3 m on the floor: a glossy white dielectric (roughness 0.2), a
  blue rough dielectric (roughness 0.6) and gold (metal, base colour (1.0, 0.78, 0.34),
  roughness 0.3);
- camera "Camera": perspective, yfov 1.0 rad, aspectRatio 1, at (0, 1.4, 1.9) looking at
  (0, 0.6, -0.6);
- KHR_lights_punctual: "Ceiling Lamp", a point light of 1200 cd (1.76 W/sr) colour (1, 0.9,
  0.75) at (0, 2.3, 0); "Spot", a spot light of 4000 cd at (1.6, 2.3, 1.6) aimed at the gold
  sphere, outer cone 0.5 rad, inner 0.35 rad.

Every face is one-sided, facing into the room. Run: .venv/bin/python tools/make_gltf_room.py
"""
import math
import sys
from pathlib import Path

import numpy as np

from gltf_writer import Gltf, write_models  # tools/ is on sys.path when a tool runs

OUT = Path(__file__).resolve().parent.parent / "scenes" / "references" / "gltf_room.glb"
SPHERES = OUT.with_name("gltf_spheres.glb")
ANIMATED = OUT.parent.parent / "animated_room.glb"  # the room with two animations (animate)
OAK, DARK_OAK = (196, 150, 98), (120, 82, 48)


def floor_checks():
    """64x64 RGB: 8x8 checks of two oak tones."""
    rows, cols = np.indices((64, 64)) // 8
    return np.where(((rows + cols) % 2 == 0)[..., None], OAK, DARK_OAK).astype(np.uint8)


def quad(corners):
    """Two triangles over four corners (counter-clockwise seen from the side they face),
    texture coordinates (0, 0) at the first corner's far side: the image's top-left at corner 3."""
    positions = np.array(corners, float)
    normal = np.cross(positions[1] - positions[0], positions[2] - positions[0])
    normals = np.tile(normal / np.linalg.norm(normal), (4, 1))
    texcoords = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], float)
    return positions, normals, texcoords, np.array([0, 1, 2, 0, 2, 3])


def box(size):
    """An axis-aligned box of `size` standing on y = 0, centred on x = z = 0, faces outwards."""
    sx, sy, sz = (s / 2 for s in size)
    faces = [[(-sx, 0, sz), (sx, 0, sz), (sx, 2 * sy, sz), (-sx, 2 * sy, sz)],       # +z
             [(sx, 0, -sz), (-sx, 0, -sz), (-sx, 2 * sy, -sz), (sx, 2 * sy, -sz)],   # -z
             [(sx, 0, sz), (sx, 0, -sz), (sx, 2 * sy, -sz), (sx, 2 * sy, sz)],       # +x
             [(-sx, 0, -sz), (-sx, 0, sz), (-sx, 2 * sy, sz), (-sx, 2 * sy, -sz)],   # -x
             [(-sx, 2 * sy, sz), (sx, 2 * sy, sz), (sx, 2 * sy, -sz), (-sx, 2 * sy, -sz)],  # +y
             [(-sx, 0, -sz), (sx, 0, -sz), (sx, 0, sz), (-sx, 0, sz)]]               # -y
    parts = [quad(face) for face in faces]
    positions = np.concatenate([p[0] for p in parts])
    indices = np.concatenate([p[3] + 4 * k for k, p in enumerate(parts)])
    return positions, np.concatenate([p[1] for p in parts]), np.concatenate([p[2] for p in parts]), indices


def sphere(radius, segments=48, rings=24):
    theta = np.linspace(0, math.pi, rings + 1)[:, None]
    phi = np.linspace(0, 2 * math.pi, segments + 1)[None, :]
    normals = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta) * np.ones_like(phi), -np.sin(theta) * np.sin(phi)],
                       axis=-1).reshape(-1, 3)
    texcoords = np.stack(np.broadcast_arrays(phi / (2 * math.pi), theta / math.pi), axis=-1).reshape(-1, 2)
    indices = []
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            if i > 0:
                indices += [a, b, a + 1]
            if i < rings - 1:
                indices += [a + 1, b, b + 1]
    return normals * radius, normals, texcoords, np.array(indices)


def look_rotation(eye, target):
    """glTF quaternion (x, y, z, w) turning -z towards target - eye, +y up."""
    forward = np.asarray(target, float) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    m = np.column_stack([right, up, -forward])
    w = math.sqrt(max(1.0 + m[0, 0] + m[1, 1] + m[2, 2], 1e-12)) / 2
    return [(m[2, 1] - m[1, 2]) / (4 * w), (m[0, 2] - m[2, 0]) / (4 * w), (m[1, 0] - m[0, 1]) / (4 * w), w]


def material(g, name, color, roughness, metallic=0.0, texture=None, tiles=None):
    pbr = {"baseColorFactor": [*color, 1.0], "metallicFactor": metallic, "roughnessFactor": roughness}
    if texture is not None:
        pbr["baseColorTexture"] = {"index": texture, "extensions": {"KHR_texture_transform": {"scale": tiles}}}
    return g.add("materials", {"name": name, "pbrMetallicRoughness": pbr})


def build(animated=False):
    """The room; `animated`: with the animations of ANIMATED (see main)."""
    g = Gltf("tools/make_gltf_room.py")
    g.doc["extensionsUsed"] = ["KHR_lights_punctual", "KHR_texture_transform"]
    g.add("samplers", {"wrapS": 10497, "wrapT": 10497})
    floor_material = material(g, "Oak Floor", (1.0, 1.0, 1.0), 0.5, texture=g.texture(floor_checks(), "oak"), tiles=[4, 4])
    wall, back, ceiling = (material(g, name, color, 0.9) for name, color in (
        ("Wall", (0.75, 0.72, 0.66)), ("Terracotta", (0.65, 0.30, 0.20)), ("Ceiling", (0.8, 0.8, 0.8))))
    h, top = 2.0, 2.5
    surfaces = {"Floor": ([(-h, 0, -h), (-h, 0, h), (h, 0, h), (h, 0, -h)], floor_material),
                "Ceiling": ([(-h, top, h), (-h, top, -h), (h, top, -h), (h, top, h)], ceiling),
                "Back Wall": ([(-h, 0, -h), (h, 0, -h), (h, top, -h), (-h, top, -h)], back),
                "Front Wall": ([(h, 0, h), (-h, 0, h), (-h, top, h), (h, top, h)], wall),
                "Left Wall": ([(-h, 0, h), (-h, 0, -h), (-h, top, -h), (-h, top, h)], wall),
                "Right Wall": ([(h, 0, -h), (h, 0, h), (h, top, h), (h, top, -h)], wall)}
    roots = [g.add("nodes", {"name": name, "mesh": g.mesh(name, quad(corners), m)}) for name, (corners, m) in surfaces.items()]
    blocks = box((0.6, 0.9, 0.6))
    ramp = (blocks[0][:, 1:2] / 0.9) * np.array([[-0.9, 0.0, 0.9]]) + np.array([[0.95, 0.1, 0.05]])  # red -> blue
    painted = g.mesh("Painted Block", blocks, material(g, "Vertex Coloured", (1.0, 1.0, 1.0), 0.8), colors=ramp)
    angle = math.radians(25.0)
    roots.append(g.add("nodes", {"name": "Painted Block", "mesh": painted, "translation": [-1.1, 0, -0.9],
                                 "rotation": [0.0, math.sin(angle / 2), 0.0, math.cos(angle / 2)]}))
    spheres = [("Glossy White", (0.8, 0.8, 0.8), 0.2, 0.0, -0.35), ("Blue", (0.1, 0.2, 0.6), 0.6, 0.0, 0.35),
               ("Gold", (1.0, 0.78, 0.34), 0.3, 1.0, 1.05)]
    for name, color, roughness, metallic, x in spheres:
        mesh = g.mesh(name, sphere(0.3), material(g, name, color, roughness, metallic))
        roots.append(g.add("nodes", {"name": name, "mesh": mesh, "translation": [x, 0.3, -0.6]}))
    camera = g.add("cameras", {"name": "Camera", "type": "perspective",
                               "perspective": {"yfov": 1.0, "aspectRatio": 1.0, "znear": 0.05, "zfar": 50.0}})
    eye = np.array([0.0, 1.4, 1.9])
    roots.append(g.add("nodes", {"name": "Camera", "camera": camera, "translation": eye.tolist(),
                                 "rotation": look_rotation(eye, [0.0, 0.6, -0.6])}))
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "Ceiling Lamp", "type": "point", "color": [1.0, 0.9, 0.75], "intensity": 1200.0},
        {"name": "Spot", "type": "spot", "color": [1.0, 1.0, 1.0], "intensity": 4000.0,
         "spot": {"innerConeAngle": 0.35, "outerConeAngle": 0.5}}]}}
    roots.append(g.add("nodes", {"name": "Ceiling Lamp", "translation": [0.0, 2.3, 0.0],
                                 "extensions": {"KHR_lights_punctual": {"light": 0}}}))
    spot = np.array([1.6, 2.3, 1.6])
    roots.append(g.add("nodes", {"name": "Spot", "translation": spot.tolist(), "rotation": look_rotation(spot, [1.05, 0.3, -0.6]),
                                 "extensions": {"KHR_lights_punctual": {"light": 1}}}))
    g.doc["scenes"][0]["nodes"] = roots
    if animated:
        animate(g, dict(zip([g.doc["nodes"][n]["name"] for n in roots], roots)), eye, spot)
    return g.glb()


def quaternion_y(degrees):
    half = math.radians(degrees) / 2
    return [0.0, math.sin(half), 0.0, math.cos(half)]


def animate(g, nodes, eye, spot):
    """ANIMATED's two animations. "Play" (4 s): the blue sphere rolls 1 m towards the camera
    and back (LINEAR), the painted block turns a full turn about y (LINEAR, from its 25
    degrees), the glossy white sphere shrinks to 0.7 at 2 s (STEP), the spot sweeps from the
    gold sphere to the blue one and back (CUBICSPLINE, zero tangents). "Dolly" (6 s): the
    camera moves 0.5 m to the right and back (CUBICSPLINE)."""
    blue = [0.35, 0.3, -0.6]
    g.animation("Play", [
        (nodes["Blue"], "translation", [0, 2, 4], [blue, [0.35, 0.3, 0.4], blue], "LINEAR"),
        (nodes["Painted Block"], "rotation", [0, 1, 2, 3, 4], [quaternion_y(25 + 90 * k) for k in range(5)], "LINEAR"),
        (nodes["Glossy White"], "scale", [0, 2], [[1, 1, 1], [0.7, 0.7, 0.7]], "STEP"),
        (nodes["Spot"], "rotation", [0, 2, 4],
         [v for aim in ([1.05, 0.3, -0.6], [0.35, 0.3, -0.6], [1.05, 0.3, -0.6])
          for v in ([0, 0, 0, 0], look_rotation(spot, aim), [0, 0, 0, 0])], "CUBICSPLINE")])
    g.animation("Dolly", [
        (nodes["Camera"], "translation", [0, 3, 6],
         [v for p in (eye, eye + [0.5, 0, 0], eye) for v in ([0, 0, 0], list(p), [0, 0, 0])], "CUBICSPLINE")])


def build_spheres():
    """Six spheres of radius 0.22 m on the Cornell box's floor (y = -1): a white dielectric
    (base colour 0.8) at roughness 0.1, 0.4 and 0.8 in the back row (z = -0.45) and gold metal
    (1.0, 0.78, 0.34) at the same roughnesses in the front row (z = 0.15)."""
    g = Gltf("tools/make_gltf_room.py")
    roots = []
    for row, (kind, color, metallic, z) in enumerate((("Dielectric", (0.8, 0.8, 0.8), 0.0, -0.45),
                                                      ("Gold", (1.0, 0.78, 0.34), 1.0, 0.15))):
        for k, roughness in enumerate((0.1, 0.4, 0.8)):
            name = f"{kind} {roughness}"
            mesh = g.mesh(name, sphere(0.22), material(g, name, color, roughness, metallic))
            roots.append(g.add("nodes", {"name": name, "mesh": mesh, "translation": [-0.55 + 0.55 * k, -0.78, z]}))
    g.doc["scenes"][0]["nodes"] = roots
    return g.glb()


def main():
    write_models([(OUT, build()), (SPHERES, build_spheres()), (ANIMATED, build(animated=True))])


if __name__ == "__main__":
    sys.exit(main())
