"""The limits every input is held to: one set, whether a node, transform or material comes from
a scene file, a glTF file or an OBJ/MTL file, and the checks that apply them (plain numpy, no
GL). docs/USAGE.md's "Limits" table states each one.

Each check takes `fail(field, message)`, the caller's way of raising SceneError with the field
named as its file names it (`objects[2] "Lamp".scale`, `materials[3].emissiveFactor`,
`line 12 (Ke)`)."""
import numpy as np

from .constants import VOXEL_MAX_EMISSION

# Numbers: every number read is within +-MAX_MAGNITUDE unless a tighter bound is given (metres,
# degrees, W/sr, W/m^2); larger values overflow float32 on the GPU once squared or summed.
MAX_MAGNITUDE = 1e6
# Every world transform scales by MIN_SCALE..MAX_MAGNITUDE along each axis (invertible in
# float32), and what a node places (its mesh, its light, itself) lies within +-MAX_MAGNITUDE.
MIN_SCALE = 1e-6
# Emitted radiance, W/(m^2 sr): the G-buffer holds it in half floats, the voxels clamp to it.
MAX_EMISSION = VOXEL_MAX_EMISSION
MIN_FOV_DEG = 0.01
# Levels of nested nodes below the scene's top level, a mesh file's own nodes counted in.
MAX_DEPTH = 32

# Files: each is read only if it is a regular file (never a device such as /dev/zero, nor a
# pipe), up to its size; everything one scene reads together stays within MAX_INPUT_BYTES.
MAX_SCENE_BYTES = 4 * 2 ** 20
MAX_FILE_BYTES = 256 * 2 ** 20       # each mesh file, glTF buffer, material library, image
MAX_INPUT_BYTES = 2 ** 30            # all the files of one scene
MAX_REFERENCE_BYTES = 2 ** 30        # a `bench --reference` array
MAX_SHADER_BYTES = 2 ** 20           # each GLSL file
MAX_INCLUDE_DEPTH = 32               # nested #include levels
# What a glTF file's data decodes to, checked from the counts before anything is made: its
# accessors together (each counted once; an accessor without a buffer view is zeros of its
# count), and the triangles of each mesh file once strips and fans are expanded.
MAX_DECODED_BYTES = 2 ** 30
MAX_FILE_TRIANGLES = 2 ** 23
# Images decode within these bounds, checked from their headers before any pixel is decoded.
MAX_IMAGE_SIDE = 16384               # pixels on a side (the GL limit is checked at upload)
MAX_IMAGE_PIXELS = 2 ** 26           # each image: 8192 x 8192
MAX_INPUT_PIXELS = 2 ** 28           # all distinct images of one scene together

# The material fields and their ranges: (low, high), each channel of a colour within it.
MATERIAL_RANGES = {
    "albedo": (0.0, 1.0),
    "roughness": (0.0, 1.0),
    "metalness": (0.0, 1.0),
    "specular": (0.0, 1.0),
    "emission": (0.0, MAX_EMISSION),
    "alpha": (0.0, 1.0),
    "alpha_cutoff": (0.0, MAX_MAGNITUDE),
    "normal_scale": (-MAX_MAGNITUDE, MAX_MAGNITUDE),
}


def check_material(material, fail, fields):
    """Every field of `material` within MATERIAL_RANGES; `fields` maps a field's name to what
    the material's file calls it (a field it does not name is called by its own name)."""
    for name, (low, high) in MATERIAL_RANGES.items():
        values = np.atleast_1d(np.asarray(getattr(material, name), float))
        bad = ~np.isfinite(values) | (values < low) | (values > high)
        if bad.any():
            value = values[np.argmax(bad)]
            per_channel = " per channel" if values.size > 1 else ""
            fail(fields.get(name, name), f"{name} must be within {low:g}..{high:g}{per_channel}, got {value:.6g}")


def check_placement(node, world, fail):
    """The node's world transform must be invertible within float32 (it scales by
    MIN_SCALE..MAX_MAGNITUDE along every axis), and what it places (its mesh, its light, or
    its origin) must lie within +-MAX_MAGNITUDE of the origin. `fail(attribute, message)`
    takes "scale", "position" (a light's) or "translation"."""
    if not np.all(np.isfinite(world)):
        fail("scale", "its world transform (its parents', its own) is not finite")
    scales = np.linalg.svd(world[:3, :3], compute_uv=False)
    if not MIN_SCALE <= scales.min() <= scales.max() <= MAX_MAGNITUDE:
        fail("scale", f"its world transform (its parents', its own, its size) scales by {scales.min():.3g}.."
                      f"{scales.max():.3g}; each must be within {MIN_SCALE:g}..{MAX_MAGNITUDE:g}")
    if node.mesh is not None:
        lo, hi = node.mesh.bounds(world)
        reach, attribute = max(np.abs(lo).max(), np.abs(hi).max()), None
    elif node.light is not None:
        position = world[:3, :3] @ node.light.position + world[:3, 3]
        reach, attribute = np.abs(position).max(), "position"
    else:
        reach, attribute = np.abs(world[:3, 3]).max(), "translation"
    if reach > MAX_MAGNITUDE:
        fail(attribute, f"reaches {reach:.3g} m from the origin along an axis in the world, beyond {MAX_MAGNITUDE:g}")


def check_vertices(values, fail):
    """Every component of the (count, width) `values` finite and within +-MAX_MAGNITUDE;
    `fail(message)` names the first element that is not."""
    bad = ~np.isfinite(values) | (np.abs(values) > MAX_MAGNITUDE)
    if bad.any():
        element = int(np.argmax(bad.any(axis=1)))
        fail(f"element {element} is {values[element].tolist()}: each component must be finite and within "
             f"+-{MAX_MAGNITUDE:g}")
