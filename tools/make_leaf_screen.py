"""Writes scenes/references/leaf_screen.glb, the glTF model of the `leaf_screen` reference scene
(scenes/references/leaf_screen.json), with numpy and json (and Pillow for the PNG image):

- node "Leaves": a 0.9 x 1.3 m quad standing on the Cornell box's floor at z = -0.2101 (inside
  one voxel of the 32^3, 64^3 and 128^3 grids over the room), facing the camera (+z), whose
  RGBA texture LEAVES (64x64) is a green screen of leaf-shaped blobs with gaps between them
  (alpha 0 in a third of it). Material "Leaves": alphaMode MASK, alphaCutoff 0.5, doubleSided,
  as foliage and cloth are made: one surface seen, lit and reflecting from both sides.

glTF texture coordinates: (0, 0) is the image's top-left. Run: .venv/bin/python tools/make_leaf_screen.py
"""
import sys
from pathlib import Path

import numpy as np

from gltf_writer import Gltf, unit_quad, write_models  # tools/ is on sys.path when a tool runs

OUT = Path(__file__).resolve().parent.parent / "scenes" / "references" / "leaf_screen.glb"
LEAF_GREEN = (60, 150, 50)


def leaves():
    """64x64 RGBA: opaque leaf-green ellipses on a grid of 8x8 cells (each 8 px, its ellipse
    3.6 x 2.8 px in radius, turned alternately), transparent between them."""
    y, x = np.mgrid[0:64, 0:64] + 0.5
    cell_x, cell_y = (x % 8) - 4.0, (y % 8) - 4.0
    turned = ((x // 8 + y // 8) % 2) == 1
    u = np.where(turned, cell_y, cell_x)
    v = np.where(turned, cell_x, cell_y)
    inside = (u / 3.6) ** 2 + (v / 2.8) ** 2 <= 1.0
    image = np.zeros((64, 64, 4), np.uint8)
    image[..., :3] = LEAF_GREEN
    image[..., 3] = np.where(inside, 255, 0)
    return image


def build():
    g = Gltf("tools/make_leaf_screen.py")
    g.add("samplers", {"wrapS": 10497, "wrapT": 10497})
    material = g.add("materials", {"name": "Leaves", "alphaMode": "MASK", "alphaCutoff": 0.5, "doubleSided": True,
                                   "pbrMetallicRoughness": {"baseColorTexture": {"index": g.texture(leaves(), "leaves")},
                                                            "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    mesh = g.mesh("Leaves", unit_quad(), material)
    g.add("nodes", {"name": "Leaves", "mesh": mesh, "translation": [0.0, -0.35, -0.2101], "scale": [0.9, 1.3, 1.0]})
    g.doc["scenes"][0]["nodes"] = [0]
    return g.glb()


def main():
    write_models([(OUT, build())])


if __name__ == "__main__":
    sys.exit(main())
