"""Writes scenes/city_block.json: a scene several hundred metres across, larger than one voxel
grid can hold in detail: the Sponza courtyard (scenes/sponza/) at the centre of a city of box
buildings 400 m wide, under the daylight sky and sun of scenes/sponza.json, with its camera
in the courtyard, where near detail matters.

The city: 10 x 10 blocks 40 m apart (the streets 12 m wide between building plots of 28 m),
the four around the courtyard left open as a square; on each plot one building, its
footprint 16-28 m a side, 8-45 m tall, turned by up to 10 degrees, of one of four facade
materials, drawn from a fixed seed, so the file is the same at every run. The ground is one
asphalt quad 7 cm under the courtyard's floor. The voxels: a clipmap of 8 levels of 64^3 from
5 cm voxels around the camera, its coarsest level 410 m wide. Run: .venv/bin/python tools/make_city_block.py
"""
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "scenes" / "city_block.json"

CITY_SIZE = 400.0    # metres along x and z
BLOCK_PITCH = 40.0   # block centres apart: a 28 m plot and a 12 m street
SEED = 24
FACADES = {
    "concrete": {"albedo": [0.55, 0.53, 0.50]},
    "brick": {"albedo": [0.45, 0.25, 0.18]},
    "sandstone": {"albedo": [0.62, 0.52, 0.38]},
    "dark_glass": {"albedo": [0.18, 0.20, 0.23], "roughness": 0.35},
}
GROUND_HEIGHT = -0.1  # under the courtyard's floor (y = -0.03)
CLIPMAP = {"levels": 8, "resolution": 64, "voxel_size": 0.05}  # level 7: 64 x 6.4 m, the whole city


def buildings(rng):
    """The city's box nodes, block by block, the blocks around the courtyard left open."""
    centres = np.arange(-CITY_SIZE / 2 + BLOCK_PITCH / 2, CITY_SIZE / 2, BLOCK_PITCH)
    nodes = []
    for x in centres:
        for z in centres:
            if abs(x) < BLOCK_PITCH and abs(z) < BLOCK_PITCH:  # the square around the courtyard
                continue
            width, depth = rng.uniform(16.0, 28.0, size=2)
            height = rng.uniform(8.0, 45.0)
            nodes.append({"name": f"Building {len(nodes) + 1}", "type": "box",
                          "material": str(rng.choice(list(FACADES))),
                          "center": [round(float(x), 3), round(height / 2 + GROUND_HEIGHT, 3), round(float(z), 3)],
                          "size": [round(float(width), 3), round(float(height), 3), round(float(depth), 3)],
                          "rotation_y_deg": round(float(rng.uniform(-10.0, 10.0)), 2)})
    return nodes


def scene():
    half = CITY_SIZE / 2
    ground = {"name": "Streets", "type": "quad", "material": "asphalt",
              "vertices": [[-half, GROUND_HEIGHT, -half], [-half, GROUND_HEIGHT, half], [half, GROUND_HEIGHT, half],
                           [half, GROUND_HEIGHT, -half]]}
    return {
        "name": "city_block",
        "about": ("The Sponza courtyard (scenes/sponza/, CC BY 3.0 Frank Meinl, Crytek) at the centre of a 400 m city "
                  "of box buildings (tools/make_city_block.py), under the daylight sky and sun of scenes/sponza.json: "
                  "a scene larger than one voxel grid holds in detail. Meters, +y up; the camera is sponza.json's, in "
                  "the courtyard."),
        "camera": {"position": [-8.0, 1.5, -0.28], "look_at": [5.0, 3.4, -0.28], "up": [0.0, 1.0, 0.0],
                   "vertical_fov_deg": 65.0, "width": 256, "height": 256},
        "materials": {"asphalt": {"albedo": [0.12, 0.12, 0.12]}, **FACADES},
        "objects": [{"name": "Sponza", "type": "mesh", "file": "sponza/sponza_512.glb"}, ground,
                    *buildings(np.random.default_rng(SEED))],
        "voxel_region": {"clipmap": CLIPMAP},
        "environment": {"map": "sky/daylight.exr"},
        "lights": [
            {"name": "Sun", "type": "directional", "direction": [0.35, -1.0, 0.2], "irradiance": [4.0, 3.8, 3.4]},
            {"name": "Courtyard Lamp", "type": "point", "position": [2.0, 2.0, -0.28], "intensity": [20.0, 15.0, 10.0]},
        ],
    }


def main():
    OUT.write_text(json.dumps(scene(), indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
