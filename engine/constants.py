"""Constants shared by the host and the shaders, defined once.

`glsl_header()` turns them into the virtual include "engine_constants.glsl", so a
binding point or a cone table can never differ between Python and GLSL.
"""
import math

import numpy as np

# Texture units (sampler bindings).
TEXTURE_UNIT = {
    "GBUF_POSITION": 0,
    "GBUF_NORMAL": 1,
    "GBUF_ALBEDO": 2,
    "GBUF_EMISSION": 3,
    "SHADOW_ATLAS": 4,
    "VOXEL_RADIANCE": 5,
    "VOXEL_NORMAL": 6,
    "VOXEL_ALBEDO": 7,
    "HDR_INPUT": 8,
    "DIRECT_LIGHT": 9,
    "VOXEL_DIRECTIONAL": 10,  # 6 consecutive units: radiance seen by cones, by face (+x, -x, +y, -y, +z, -z)
    "VOXEL_INSPECT": 16,      # the volume a voxel view or a readback reads
    "DIFFUSE_GATHER": 17,     # the half-resolution diffuse/AO gather
}

# Image units (imageLoad/imageStore/imageAtomic* bindings).
IMAGE_UNIT = {
    "SUM_RADIANCE_R": 0,
    "SUM_RADIANCE_G": 1,
    "SUM_RADIANCE_B": 2,
    "SUM_COUNT": 3,
    "SUM_NORMAL_X": 4,
    "SUM_NORMAL_Y": 5,
    "SUM_NORMAL_Z": 6,
    "SUM_ALBEDO_R": 7,
    "SUM_ALBEDO_G": 8,
    "SUM_ALBEDO_B": 9,
    "OUT_RADIANCE": 10,
    "OUT_NORMAL": 11,
    "OUT_ALBEDO": 12,
    "OUT_DIRECTIONAL": 13,    # 6 consecutive units
    "OTHER_DIRECTIONAL": 19,  # 6 consecutive units: the other face set, cleared with the first
    "GATHERED": 25,           # the bounce pass's last gather per voxel (amortized bounces)
}

# Shader storage buffer bindings.
STORAGE_BINDING = {
    "LIGHTS": 0,
    "SHADOW_MATRICES": 1,
    "READBACK": 2,
    "OCCUPIED": 3,
    "PREVIOUS_OCCUPIED": 4,
}

MAX_LIGHTS = 16

LIGHT_TYPE = {"point": 0, "spot": 1, "directional": 2}

# Voxel sums are fixed point: value * VOXEL_FIXED_SCALE stored in 32 bits.
# Headroom: VOXEL_MAX_FRAGMENTS * VOXEL_MAX_VALUE * VOXEL_FIXED_SCALE < 2^32.
VOXEL_FIXED_SCALE = 4096.0
VOXEL_MAX_FRAGMENTS = 256
VOXEL_MAX_VALUE = (2.0 ** 32 - 1) / (VOXEL_FIXED_SCALE * VOXEL_MAX_FRAGMENTS)  # 4095.99
VOXEL_NORMAL_SCALE = 65536.0  # signed sums of unit normals: 256 * 65536 < 2^31

# GL formats of the resolved voxel textures and the render targets.
VOXEL_FORMAT = "f2"  # RGBA16F: HDR radiance without banding (field notes 9)
HDR_FORMAT = "f4"
GL_IMAGE_FORMAT = {"r32ui": 0x8236, "r32i": 0x8235, "rgba16f": 0x881A}
# Voxel memory allowed before a grid is refused (bytes); the 256^3 grid needs about 3 GiB.
VOXEL_MEMORY_BUDGET = 4 * 2 ** 30
# One-sided views of the voxel radiance that cones read, one per axis direction (+x, -x, ...).
VOXEL_FACES = 6

GRID_SIZES = (16, 32, 64, 128, 256)

# Compute shader local sizes: passes over the list of covered voxels, and over a whole volume.
LIST_GROUP = 64
VOLUME_GROUP = 4


def cone_cosine_centroid_tilt(tilt, half_angle, samples=400):
    """Polar angle of the cosine-weighted mean direction of a cone (axis `tilt` from the normal,
    half-angle `half_angle`), by midpoint quadrature over the cone's solid angle. A cone is
    marched as one ray of growing width, which averages radiance evenly over its solid angle;
    the diffuse integrand is cosine weighted, so the cone is marched along the direction that
    weighting pulls it to (first-order centroid rule). The weights are unchanged."""
    theta = (np.arange(samples) + 0.5) / samples * half_angle  # angle from the cone axis
    phi = (np.arange(samples) + 0.5) / samples * 2.0 * math.pi
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    # Ray directions with the cone axis tilted by `tilt` about y in the normal's frame (z = normal).
    x = np.sin(theta) * np.cos(phi)
    z = np.cos(theta)
    y = np.sin(theta) * np.sin(phi)
    dx = x * math.cos(tilt) + z * math.sin(tilt)
    dz = -x * math.sin(tilt) + z * math.cos(tilt)
    weight = np.sin(theta) * np.clip(dz, 0.0, None)  # solid angle element * cosine to the normal
    mean = np.array([(dx * weight).sum(), (y * weight).sum(), (dz * weight).sum()])
    return math.acos(mean[2] / np.linalg.norm(mean))


def diffuse_cones():
    """The lecture's 6 diffuse/AO cones in the local frame (z = normal).

    Returns (directions (6,3), weights (6,), half_angle). One central cone along the normal
    with weight 1/4, five around it, 72 degrees apart, covering 30..90 degrees from the
    normal (centred at 60 degrees), 3/20 each; every cone has half-angle pi/6, so the set
    tiles the hemisphere and the weights are the cosine-weighted shares of their regions
    (sin^2 30 = 1/4 for the central cap). The five are marched along their regions' cosine
    centroid (52.8 degrees), see cone_cosine_centroid_tilt.
    """
    half_angle = math.pi / 6.0
    region_tilt = math.radians(60.0)
    march_tilt = cone_cosine_centroid_tilt(region_tilt, half_angle)
    directions = [(0.0, 0.0, 1.0)]
    for k in range(5):
        phi = math.radians(72.0 * k)
        directions.append((math.sin(march_tilt) * math.cos(phi), math.sin(march_tilt) * math.sin(phi), math.cos(march_tilt)))
    weights = [0.25] + [3.0 / 20.0] * 5
    assert abs(sum(weights) - 1.0) < 1e-12, "diffuse cone weights must sum to 1"
    return np.array(directions), np.array(weights), half_angle


def glsl_header():
    """GLSL source of the virtual include "engine_constants.glsl"."""
    lines = ["// Generated from engine/constants.py: edit there, not here."]
    for group, prefix in ((TEXTURE_UNIT, "TEX_"), (IMAGE_UNIT, "IMG_"), (STORAGE_BINDING, "SSBO_")):
        lines += [f"#define {prefix}{name} {value}" for name, value in group.items()]
    lines += [f"#define LIGHT_{name.upper()} {value}" for name, value in LIGHT_TYPE.items()]
    lines += [
        f"#define MAX_LIGHTS {MAX_LIGHTS}",
        f"#define LIST_GROUP {LIST_GROUP}",
        f"#define VOXEL_FACES {VOXEL_FACES}",
        f"#define VOLUME_GROUP {VOLUME_GROUP}",
        f"#define VOXEL_FIXED_SCALE {VOXEL_FIXED_SCALE:.1f}",
        f"#define VOXEL_MAX_FRAGMENTS {VOXEL_MAX_FRAGMENTS}",
        f"#define VOXEL_MAX_VALUE {VOXEL_MAX_VALUE:.3f}",
        f"#define VOXEL_NORMAL_SCALE {VOXEL_NORMAL_SCALE:.1f}",
        "#define PI 3.14159265358979",
    ]
    directions, weights, half_angle = diffuse_cones()
    lines.append(f"#define DIFFUSE_CONE_COUNT {len(weights)}")
    lines.append(f"#define DIFFUSE_CONE_HALF_ANGLE {half_angle:.9f}")
    dirs = ", ".join(f"vec3({d[0]:.9f}, {d[1]:.9f}, {d[2]:.9f})" for d in directions)
    lines.append(f"const vec3 DIFFUSE_CONE_DIRECTIONS[{len(weights)}] = vec3[]({dirs});")
    ws = ", ".join(f"{w:.9f}" for w in weights)
    lines.append(f"const float DIFFUSE_CONE_WEIGHTS[{len(weights)}] = float[]({ws});")
    return "\n".join(lines) + "\n"
