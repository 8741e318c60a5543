"""Writes scenes/sky/daylight.exr: a clear daylight sky as an equirectangular map of linear
radiance (256 x 128 float RGB OpenEXR, engine.scene.model.Environment's convention: row 0 looks
straight up, the left edge along -z), made from a formula:

- above the horizon, a blue zenith (0.10, 0.20, 0.45) W/(m^2 sr) brightening towards a hazy
  horizon (0.45, 0.50, 0.55) as (1 - sin(elevation))^2, and a circumsolar glow around the sun
  of scenes/sponza.json (it travels along (0.35, -1, 0.2): the glow is centred on the opposite
  direction) of 1.5 x exp(-angle / 0.15 rad) times the horizon colour; the sun's disc itself is
  not in the map (the scene's directional light is the sun);
- below the horizon, the ground's light (0.06, 0.055, 0.05), constant.

Its irradiance on a horizontal surface from the upper half is about (0.6, 0.9, 1.6) W/m^2, a
quarter of the sun's 4 W/m^2 in scenes/sponza.json. Run: .venv/bin/python tools/make_sky.py
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from engine.formats.output import save_exr  # noqa: E402

OUT = ROOT / "scenes" / "sky" / "daylight.exr"
ZENITH = np.array([0.10, 0.20, 0.45])
HORIZON = np.array([0.45, 0.50, 0.55])
GROUND = np.array([0.06, 0.055, 0.05])
SUN_TRAVEL = np.array([0.35, -1.0, 0.2])


def directions(width, height):
    """The unit direction each texel's centre looks along (u = atan2(x, -z) / 2 pi, v = acos(y) / pi)."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi, theta = np.meshgrid(2.0 * np.pi * u, np.pi * v)
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)


def daylight(width=256, height=128):
    d = directions(width, height)
    elevation = np.clip(d[..., 1], 0.0, 1.0)[..., None]
    sky = ZENITH + (HORIZON - ZENITH) * (1.0 - elevation) ** 2
    to_sun = -SUN_TRAVEL / np.linalg.norm(SUN_TRAVEL)
    angle = np.arccos(np.clip(d @ to_sun, -1.0, 1.0))[..., None]
    sky = sky + 1.5 * HORIZON * np.exp(-angle / 0.15)
    return np.where(d[..., 1:2] >= 0.0, sky, GROUND).astype(np.float32)


if __name__ == "__main__":
    OUT.parent.mkdir(exist_ok=True)
    save_exr(OUT, daylight())
    print(f"wrote {OUT.relative_to(ROOT)}")
