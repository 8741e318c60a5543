"""Writes scenes of many objects, for measuring what a frame costs as the objects grow in number
while the pixels stay the same: a field of boxes on a ground (scene files of `box` objects,
which share one mesh) and a field of instances of one mesh (a GLB whose nodes all use its one
mesh, placed by a scene file on the same ground).

    .venv/bin/python tools/make_many_objects.py [--out out/many_objects] [--boxes 64,4096]
        [--instances 64,65536]

writes boxes_<N>.json, instances_<N>.json and instances_<N>.glb into --out. Every scene is the
same 32 m square of ground under the same sun and lamp, seen by the same camera; the N objects
stand on a sqrt(N) x sqrt(N) lattice over it, each half its lattice step wide (a box: 12
triangles; an instance: an icosahedral pebble of 20), their heights, turns and materials drawn
from a fixed seed, so a file is the same at every run."""
import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from gltf_writer import Gltf  # noqa: E402  (a tool beside this one)

ROOT = Path(__file__).resolve().parent.parent
GROUND_SIZE = 32.0  # metres, the square the objects stand on
SEED = 46
MATERIALS = {
    "ground": {"albedo": [0.45, 0.45, 0.42]},
    "clay": {"albedo": [0.70, 0.35, 0.25]},
    "moss": {"albedo": [0.25, 0.50, 0.20]},
    "chalk": {"albedo": [0.80, 0.80, 0.78]},
    "slate": {"albedo": [0.25, 0.28, 0.35], "roughness": 0.4, "specular": 0.04},
}
OBJECT_MATERIALS = ["clay", "moss", "chalk", "slate"]


def lattice(count):
    """(x, z) centres of a sqrt(count)^2 lattice over the ground, and its step."""
    side = math.isqrt(count)
    if side * side != count:
        sys.exit(f"make_many_objects: {count} is not a square number")
    step = GROUND_SIZE / side
    centres = (np.arange(side) + 0.5) * step - GROUND_SIZE / 2
    x, z = np.meshgrid(centres, centres, indexing="ij")
    return np.stack([x.ravel(), z.ravel()], axis=1), step


def base_scene(name, about, objects):
    half = GROUND_SIZE / 2
    ground = {"name": "Ground", "type": "quad", "material": "ground",
              "vertices": [[-half, 0.0, -half], [-half, 0.0, half], [half, 0.0, half], [half, 0.0, -half]]}
    return {
        "name": name,
        "about": about + " Metres, +y up; written by tools/make_many_objects.py.",
        "camera": {"position": [-19.0, 9.0, -19.0], "look_at": [0.0, 0.0, 0.0], "vertical_fov_deg": 55.0,
                   "width": 256, "height": 256},
        "materials": MATERIALS,
        "objects": [ground, *objects],
        "lights": [
            {"name": "Sun", "type": "directional", "direction": [0.4, -1.0, 0.25], "irradiance": [3.0, 2.9, 2.7]},
            {"name": "Lamp", "type": "point", "position": [2.0, 3.0, -1.0], "intensity": [30.0, 24.0, 18.0]},
        ],
    }


def boxes(count):
    rng = np.random.default_rng(SEED)
    centres, step = lattice(count)
    objects = []
    for index, (x, z) in enumerate(centres):
        width = 0.5 * step
        height = float(rng.uniform(0.3, 1.5)) * width
        objects.append({"name": f"Box {index + 1}", "type": "box", "material": OBJECT_MATERIALS[int(rng.integers(4))],
                        "center": [round(float(x), 4), round(height / 2, 4), round(float(z), 4)],
                        "size": [round(width, 4), round(height, 4), round(width, 4)],
                        "rotation_y_deg": round(float(rng.uniform(0.0, 90.0)), 2)})
    return base_scene(f"boxes_{count}", f"{count} boxes on a 32 m ground.", objects)


def pebble():
    """An icosahedron of unit radius: positions, flat normals, texture coordinates, indices."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    corners = np.array([(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
                        (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)], float)
    corners /= np.linalg.norm(corners, axis=1, keepdims=True)
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
             (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
             (8, 6, 7), (9, 8, 1)]
    positions = corners[np.array(faces).ravel()]
    normals = np.repeat(np.cross(positions[1::3] - positions[0::3], positions[2::3] - positions[0::3]), 3, axis=0)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    texcoords = np.zeros((len(positions), 2))
    return positions, normals, texcoords, np.arange(len(positions))


def instances(count):
    """The GLB of `count` pebble instances (one mesh, a node each) and the scene file that places it."""
    rng = np.random.default_rng(SEED)
    centres, step = lattice(count)
    gltf = Gltf("tools/make_many_objects.py")
    material = gltf.add("materials", {"name": "pebble", "pbrMetallicRoughness": {
        "baseColorFactor": [0.55, 0.5, 0.45, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    mesh = gltf.mesh("Pebble", pebble(), material)
    radius = 0.25 * step
    for index, (x, z) in enumerate(centres):
        scale = radius * rng.uniform(0.6, 1.0, size=3)
        angle = rng.uniform(0.0, 2.0 * math.pi)
        node = gltf.add("nodes", {"name": f"Pebble {index + 1}", "mesh": mesh,
                                  "translation": [round(float(x), 4), round(float(0.6 * scale[1]), 4), round(float(z), 4)],
                                  "rotation": [0.0, round(math.sin(angle / 2), 6), 0.0, round(math.cos(angle / 2), 6)],
                                  "scale": [round(float(s), 4) for s in scale]})
        gltf.doc["scenes"][0]["nodes"].append(node)
    scene = base_scene(f"instances_{count}", f"{count} instances of one pebble mesh on a 32 m ground.",
                       [{"name": "Pebbles", "type": "mesh", "file": f"instances_{count}.glb"}])
    return gltf.glb(), scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "out" / "many_objects"))
    parser.add_argument("--boxes", default="64,4096", help="comma-separated box counts (square numbers)")
    parser.add_argument("--instances", default="64,65536", help="comma-separated instance counts (square numbers)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for count in (int(c) for c in args.boxes.split(",") if c):
        path = out / f"boxes_{count}.json"
        path.write_text(json.dumps(boxes(count), separators=(",", ":")) + "\n")
        print(f"wrote {path}")
    for count in (int(c) for c in args.instances.split(",") if c):
        glb, scene = instances(count)
        (out / f"instances_{count}.glb").write_bytes(glb)
        path = out / f"instances_{count}.json"
        path.write_text(json.dumps(scene, indent=1) + "\n")
        print(f"wrote {path} and instances_{count}.glb")


if __name__ == "__main__":
    main()
