"""A glTF file's cameras and KHR_lights_punctual lights."""
import math

import numpy as np

from ...core.limits import MAX_MAGNITUDE, MIN_FOV_DEG
from ...scene.model import Light, NodeCamera

LUMENS_PER_WATT = 683.0  # photometric to radiometric units at 555 nm: W/sr = cd / 683, W/m^2 = lux / 683
MAX_SPOT_ANGLE_DEG = 89.0  # a spot light's shadow is one perspective view of twice its outer angle


class CameraLightReader:
    """Part of GltfFile: the cameras and lights its nodes hold."""

    def camera(self, index):
        """The NodeCamera of cameras[index]: perspective (yfov in radians, aspectRatio) or
        orthographic (xmag, ymag: half the view's width and height)."""
        read, field = self.json, f"cameras[{index}]"
        spec = self.element("cameras", index)
        kind = read.get(spec, "type", field, kind=str)
        name = read.get(spec, "name", field, field, str)
        if kind == "perspective":
            where = f"{field}.perspective"
            lens = read.get(spec, "perspective", field, kind=dict)
            yfov = math.degrees(read.number(lens, "yfov", where, positive=True, maximum=math.radians(179.0)))
            if yfov < MIN_FOV_DEG:
                self.fail(f"{where}.yfov", f"must be at least {math.radians(MIN_FOV_DEG):g} (radians)")
            aspect = read.number(lens, "aspectRatio", where, None, positive=True) if "aspectRatio" in lens else None
            read.number(lens, "znear", where, positive=True)
            return NodeCamera(name=name, vertical_fov_deg=yfov, aspect_ratio=aspect)
        if kind == "orthographic":
            where = f"{field}.orthographic"
            lens = read.get(spec, "orthographic", field, kind=dict)
            xmag, ymag = (read.number(lens, key, where, positive=True) for key in ("xmag", "ymag"))
            read.number(lens, "znear", where, minimum=0.0)
            return NodeCamera(name=name, projection="orthographic", half_height=ymag, aspect_ratio=xmag / ymag)
        self.fail(f"{field}.type", f'must be "perspective" or "orthographic", got "{kind}"')

    def punctual_lights(self):
        extensions = self.json.get(self.doc, "extensions", "", {}, dict)
        lights = self.json.get(extensions, "KHR_lights_punctual", "extensions", {}, dict)
        return self.json.get(lights, "lights", "extensions.KHR_lights_punctual", [], list)

    def light(self, index):
        """The Light of KHR_lights_punctual's lights[index], in the node's frame (at its origin,
        shining along -z): colour x intensity in candela (point, spot) or lux (directional),
        turned into W/sr and W/m^2 at LUMENS_PER_WATT; range; the spot's cone angles."""
        read, field = self.json, f"extensions.KHR_lights_punctual.lights[{index}]"
        spec = self.punctual_lights()[index]
        if not isinstance(spec, dict):
            self.fail(field, "must be an object")
        kind = read.get(spec, "type", field, kind=str)
        if kind not in ("point", "spot", "directional"):
            self.fail(f"{field}.type", f'must be "point", "spot" or "directional", got "{kind}"')
        color = read.vector(spec, "color", field, [1.0, 1.0, 1.0], nonnegative=True)
        intensity = read.number(spec, "intensity", field, 1.0, minimum=0.0, maximum=MAX_MAGNITUDE * LUMENS_PER_WATT)
        light = Light(type=kind, intensity=color * intensity / LUMENS_PER_WATT, direction=np.array([0.0, 0.0, -1.0]))
        if kind != "directional" and "range" in spec:
            light.range = read.number(spec, "range", field, positive=True)
        if kind == "spot":
            where = f"{field}.spot"
            cone = read.get(spec, "spot", field, {}, dict)
            outer = math.degrees(read.number(cone, "outerConeAngle", where, math.pi / 4, positive=True))
            inner = math.degrees(read.number(cone, "innerConeAngle", where, 0.0, minimum=0.0))
            if outer > MAX_SPOT_ANGLE_DEG:
                self.fail(f"{where}.outerConeAngle", f"must be at most {math.radians(MAX_SPOT_ANGLE_DEG):.4f} (radians: "
                                                    f"{MAX_SPOT_ANGLE_DEG:g} degrees)")
            if inner >= outer:
                self.fail(f"{where}.innerConeAngle", "must be less than outerConeAngle")
            light.inner_angle_deg, light.outer_angle_deg = inner, outer
        return light

