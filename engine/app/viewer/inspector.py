"""Scene edits behind the Inspector panel, without GL or ImGui (the tests call them directly).

Every edit writes the scene model; the renderer reads it again on the next frame (voxels are
rebuilt every frame), so a moved light moves its shadows and its indirect light at once.
Nodes are named by their `name` in the scene graph; values are clamped to what the scene
file accepts (albedo 0..1, positive scale, ...).
"""
import copy

import numpy as np

from ...core.errors import VctError

MIN_SCALE = 1e-3


def find_node(scene, name):
    node = scene.root.find(name)
    if node is None:
        raise VctError(f'no node named "{name}"', field="scene graph")
    return node


def _vector(values, length=3):
    v = np.array(values, float).reshape(-1)
    if v.shape != (length,) or not np.all(np.isfinite(v)):
        raise VctError(f"expected {length} finite numbers, got {values!r}", field="inspector")
    return v


def _material(scene, name):
    node = find_node(scene, name)
    if node.material is None:
        raise VctError(f'"{name}" has no material', field="inspector")
    return node.material


def _light(scene, name):
    node = find_node(scene, name)
    if node.light is None:
        raise VctError(f'"{name}" is not a light', field="inspector")
    return node.light


# ---- transform ------------------------------------------------------------------------------

def set_translation(scene, name, xyz):
    find_node(scene, name).translation = _vector(xyz)


def set_rotation(scene, name, degrees_xyz):
    find_node(scene, name).rotation_deg = _vector(degrees_xyz)


def set_scale(scene, name, xyz):
    find_node(scene, name).scale = np.maximum(_vector(xyz), MIN_SCALE)


# ---- material -------------------------------------------------------------------------------

def material_users(scene, material):
    """Names of the nodes that share `material` (an edit changes all of them)."""
    return [node.name for node, _ in scene.root.walk() if node.material is material]


def make_material_unique(scene, name):
    """Give node `name` its own copy of its material, so edits change only this node."""
    node = find_node(scene, name)
    if node.material is None or len(material_users(scene, node.material)) <= 1:
        return node.material
    material = copy.deepcopy(node.material)
    base, n = f"{material.name} ({name})", 2
    material.name = base
    while material.name in scene.materials:
        material.name, n = f"{base} {n}", n + 1
    scene.materials[material.name] = material
    node.material = material
    return material


def set_albedo(scene, name, rgb):
    _material(scene, name).albedo = np.clip(_vector(rgb), 0.0, 1.0)


def set_roughness(scene, name, value):
    _material(scene, name).roughness = float(np.clip(value, 0.0, 1.0))


def set_metalness(scene, name, value):
    _material(scene, name).metalness = float(np.clip(value, 0.0, 1.0))


def set_emission(scene, name, rgb):
    _material(scene, name).emission = np.maximum(_vector(rgb), 0.0)


# ---- light ----------------------------------------------------------------------------------

def light_colour(light):
    """The light's colour: its RGB intensity divided by the brightest channel (white if dark)."""
    intensity = np.asarray(light.intensity, float)
    peak = float(intensity.max())
    return intensity / peak if peak > 0 else np.ones(3)


def light_power(light):
    """The light's scalar intensity: its brightest channel (W/sr, or W/m^2 for directional)."""
    return float(np.max(light.intensity))


def set_light_position(scene, name, xyz):
    """Move a point or spot light (the light's own position, in its node's frame)."""
    _light(scene, name).position = _vector(xyz)


def set_light_direction(scene, name, xyz):
    direction = _vector(xyz)
    norm = np.linalg.norm(direction)
    if norm == 0:
        raise VctError("direction must not be zero", field="inspector")
    _light(scene, name).direction = direction / norm


def set_light_colour(scene, name, rgb):
    """Keep the power, change the colour (normalized to a brightest channel of 1)."""
    light = _light(scene, name)
    colour = np.clip(_vector(rgb), 0.0, None)
    peak = float(colour.max())
    colour = colour / peak if peak > 0 else np.zeros(3)
    light.intensity = colour * light_power(light)


def set_light_power(scene, name, value):
    """Keep the colour, change the brightest channel to `value` (not negative)."""
    light = _light(scene, name)
    light.intensity = light_colour(light) * max(float(value), 0.0)


def set_light_cast_shadows(scene, name, enabled):
    _light(scene, name).cast_shadows = bool(enabled)
