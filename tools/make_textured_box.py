"""Writes scenes/references/textured_box.glb, the glTF model of the `textured_box` reference scene
(scenes/references/textured_box.json), with numpy and json (and Pillow for the PNG images):

- node "Painted Box": a 0.5 m cube standing on the Cornell box's floor (translation (0.4, -0.75,
  -0.5), 30 degrees about y) whose six faces each show the whole image PAINTED: 128x128 sRGB,
  bands of red/white, green/white and blue/white checks (16-pixel squares) from the image's
  top down and a black letter F, so every flip, transpose or rotation of the texture shows.
  On the four side faces the image's top is up; on the top face it points to -z (the back
  wall). Material "Painted": base colour texture, metallic 0, roughness 1 (glTF dielectric).
- node "Grille": a 0.5 m square (x 0..0.5, y 0.15..0.65) 0.5 m in front of the back wall and
  facing the camera and the light (+z), whose RGBA texture GRILLE (64x64) is a yellow lattice
  with 6x6 square holes (alpha 0) and one solid corner (the image's top-left), so it casts a
  patterned shadow of the point light, twice its size, on the back wall, half of it below the
  grille as the camera sees it. Material "Grille": alphaMode MASK, alphaCutoff 0.5,
  doubleSided.

glTF texture coordinates: (0, 0) is the image's top-left. Run: .venv/bin/python tools/make_textured_box.py
"""
import math
import sys
from pathlib import Path

import numpy as np

from gltf_writer import Gltf, unit_quad, write_models  # tools/ is on sys.path when a tool runs

OUT = Path(__file__).resolve().parent.parent / "scenes" / "references" / "textured_box.glb"

RED, GREEN, BLUE = (220, 30, 30), (30, 180, 40), (40, 60, 220)
WHITE, BLACK, YELLOW = (235, 235, 235), (20, 20, 20), (230, 190, 50)


def painted():
    """128x128 RGB: check bands red (rows of squares 0-2), green (3-5), blue (6-7), each
    alternating with white, and a black F (stem at square column 1, bars at rows 1 and 4)."""
    square = 16
    image = np.zeros((128, 128, 3), np.uint8)
    for row in range(8):
        colour = RED if row < 3 else GREEN if row < 6 else BLUE
        for col in range(8):
            image[row * square:(row + 1) * square, col * square:(col + 1) * square] = colour if (row + col) % 2 == 0 else WHITE
    f = [(r, 1) for r in range(1, 7)] + [(1, c) for c in range(2, 6)] + [(4, c) for c in range(2, 5)]
    for r, c in f:
        image[r * square:(r + 1) * square, c * square:(c + 1) * square] = BLACK
    return image


def grille():
    """64x64 RGBA: a yellow lattice (bars 4 px) around 6x6 holes of 6 px (alpha 0); the holes of
    the top-left 2x2 are filled, a solid corner."""
    image = np.zeros((64, 64, 4), np.uint8)
    image[..., :3] = YELLOW
    image[..., 3] = 255
    pitch, bar = 10, 4
    for row in range(6):
        for col in range(6):
            if row < 2 and col < 2:
                continue
            y, x = 2 + bar // 2 + row * pitch, 2 + bar // 2 + col * pitch
            image[y:y + pitch - bar, x:x + pitch - bar, 3] = 0
    return image


def cube():
    """Unit cube at the origin: 24 vertices (positions, normals, texcoords), 12 triangles, counter-
    clockwise seen from outside; each face carries the whole image, top towards `up`."""
    faces = [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)), ((0, 0, 1), (0, 1, 0)), ((0, 0, -1), (0, 1, 0)),
             ((0, 1, 0), (0, 0, -1)), ((0, -1, 0), (0, 0, 1))]
    positions, normals, texcoords, indices = [], [], [], []
    for n, up in faces:
        n, up = np.array(n, float), np.array(up, float)
        right = np.cross(up, n)  # to the right of a viewer outside, looking at the face
        base = len(positions)
        for du, dv, uv in ((-1, 1, (0, 0)), (-1, -1, (0, 1)), (1, -1, (1, 1)), (1, 1, (1, 0))):  # TL BL BR TR
            positions.append(0.5 * (n + du * right + dv * up))
            normals.append(n)
            texcoords.append(uv)
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return np.array(positions), np.array(normals), np.array(texcoords, float), np.array(indices)


def y_rotation(degrees):
    """glTF quaternion (x, y, z, w) of a rotation about +y."""
    half = math.radians(degrees) / 2
    return [0.0, math.sin(half), 0.0, math.cos(half)]


def build():
    g = Gltf("tools/make_textured_box.py")
    g.add("samplers", {"wrapS": 33071, "wrapT": 33071})  # clamp to edge; magFilter/minFilter left to the renderer
    painted_material = g.add("materials", {"name": "Painted", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": g.texture(painted(), "painted")}, "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    grille_material = g.add("materials", {"name": "Grille", "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True,
                                          "pbrMetallicRoughness": {"baseColorTexture": {"index": g.texture(grille(), "grille")},
                                                                   "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    box = g.mesh("Painted Box", cube(), painted_material)
    lattice = g.mesh("Grille", unit_quad(), grille_material)
    g.add("nodes", {"name": "Painted Box", "mesh": box, "translation": [0.4, -0.65, -0.5], "rotation": y_rotation(30.0),
                    "scale": [0.5, 0.7, 0.5]})
    g.add("nodes", {"name": "Grille", "mesh": lattice, "translation": [0.25, 0.4, -0.5], "scale": [0.5, 0.5, 1.0]})
    g.doc["scenes"][0]["nodes"] = [0, 1]
    return g.glb()


def main():
    write_models([(OUT, build())])


if __name__ == "__main__":
    sys.exit(main())
