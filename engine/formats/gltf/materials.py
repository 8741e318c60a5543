"""A glTF file's materials and their textures, with KHR_texture_transform."""
import math
from collections import namedtuple

import numpy as np

from ...core.errors import warn
from ...core.limits import check_material
from ...scene.model import ALPHA_MODES, IDENTITY_UV, Material
from .container import short_uri

GLTF_WRAP_MODES = {10497: "REPEAT", 33071: "CLAMP_TO_EDGE", 33648: "MIRRORED_REPEAT"}

TextureUse = namedtuple("TextureUse", "texture uv_set transform")


class MaterialReader:
    """Part of GltfFile: the materials of its primitives and the textures they use, each made once."""

    def primitive_material(self, spec, field):
        if "material" not in spec:
            return self.default
        return self.material(self.json.index(spec, "material", field, "materials", len(self.list("materials"))))

    def material(self, index):
        if index in self.materials:
            return self.materials[index]
        field = f"materials[{index}]"
        spec = self.element("materials", index)
        read = self.json
        pbr_field = f"{field}.pbrMetallicRoughness"
        pbr = read.get(spec, "pbrMetallicRoughness", field, {}, dict)
        base_color = read.vector(pbr, "baseColorFactor", pbr_field, [1.0, 1.0, 1.0, 1.0], length=4, nonnegative=True)
        emissive = read.vector(spec, "emissiveFactor", field, [0.0, 0.0, 0.0], nonnegative=True)
        for value, where in ((base_color, f"{pbr_field}.baseColorFactor"), (emissive, f"{field}.emissiveFactor")):
            if np.any(value > 1.0):
                self.fail(where, "must be at most 1 per channel")
        extensions = read.get(spec, "extensions", field, {}, dict)
        strength_spec = read.get(extensions, "KHR_materials_emissive_strength", f"{field}.extensions", {}, dict)
        strength = read.number(strength_spec, "emissiveStrength", f"{field}.extensions.KHR_materials_emissive_strength",
                               1.0, minimum=0.0)
        alpha_mode = read.get(spec, "alphaMode", field, "OPAQUE", str)
        if alpha_mode not in ALPHA_MODES:
            self.fail(f"{field}.alphaMode", f'must be one of {", ".join(ALPHA_MODES)}, got "{alpha_mode}"')
        uses = {"base_color_texture": self.texture(pbr, "baseColorTexture", pbr_field, srgb=True),
                "metallic_roughness_texture": self.texture(pbr, "metallicRoughnessTexture", pbr_field, srgb=False),
                "emissive_texture": self.texture(spec, "emissiveTexture", field, srgb=True),
                "normal_texture": self.texture(spec, "normalTexture", field, srgb=False)}
        normal_texture = uses["normal_texture"].texture
        material = Material(
            name=read.get(spec, "name", field, field, str),
            albedo=base_color[:3],
            alpha=float(base_color[3]),
            roughness=read.number(pbr, "roughnessFactor", pbr_field, 1.0, minimum=0.0, maximum=1.0),
            metalness=read.number(pbr, "metallicFactor", pbr_field, 1.0, minimum=0.0, maximum=1.0),
            specular=0.04,
            emission=emissive * strength,
            alpha_mode=alpha_mode,
            alpha_cutoff=read.number(spec, "alphaCutoff", field, 0.5, minimum=0.0) if alpha_mode == "MASK" else 0.5,
            double_sided=read.get(spec, "doubleSided", field, False, bool),
            normal_scale=read.number(spec["normalTexture"], "scale", f"{field}.normalTexture", 1.0) if normal_texture else 1.0,
            uv_sets={name: use.uv_set for name, use in uses.items() if use.uv_set},
            uv_transforms={name: use.transform for name, use in uses.items() if use.transform != IDENTITY_UV},
            **{name: use.texture for name, use in uses.items()},
        )
        emission_field = (f"{field}.emissiveFactor x extensions.KHR_materials_emissive_strength.emissiveStrength"
                          if strength_spec else f"{field}.emissiveFactor")
        check_material(material, self.fail, {
            "albedo": f"{pbr_field}.baseColorFactor", "alpha": f"{pbr_field}.baseColorFactor",
            "roughness": f"{pbr_field}.roughnessFactor", "metalness": f"{pbr_field}.metallicFactor",
            "emission": emission_field, "alpha_cutoff": f"{field}.alphaCutoff",
            "normal_scale": f"{field}.normalTexture.scale"})
        self.materials[index] = material
        return material

    def texture(self, obj, key, field, srgb):
        """The TextureUse of the textureInfo obj[key]: its Texture (None where there is none),
        the texture coordinate set it reads and the transform of its coordinates."""
        if key not in obj:
            return TextureUse(None, 0, IDENTITY_UV)
        read = self.json
        where = f"{field}.{key}"
        info = read.get(obj, key, field, kind=dict)
        index = read.index(info, "index", where, "textures", len(self.list("textures")))
        uv_set = int(read.number(info, "texCoord", where, 0, whole=True, minimum=0, maximum=1))
        transform = IDENTITY_UV
        extensions = read.get(info, "extensions", where, {}, dict)
        if "KHR_texture_transform" in extensions:
            uv_set, transform = self.texture_transform(extensions, f"{where}.extensions", uv_set)
        texture_field = f"textures[{index}]"
        spec = self.element("textures", index)
        if "source" not in spec:  # optional in glTF: its image may be an extension's (KHR_texture_basisu, EXT_texture_webp)
            if index not in self.sourceless:
                self.sourceless.add(index)
                warn("has no source image vct reads (images in extensions are not read): the material is drawn without it",
                     source=self.json.path, field=texture_field)
            return TextureUse(None, 0, IDENTITY_UV)
        source = read.index(spec, "source", texture_field, "images", len(self.list("images")))
        wrap = ["REPEAT", "REPEAT"]
        if "sampler" in spec:
            sampler_index = read.index(spec, "sampler", texture_field, "samplers", len(self.list("samplers")))
            sampler = self.element("samplers", sampler_index)
            for k, axis in enumerate(("wrapS", "wrapT")):
                mode = read.get(sampler, axis, f"samplers[{sampler_index}]", 10497, int)
                if mode not in GLTF_WRAP_MODES:
                    self.fail(f"samplers[{sampler_index}].{axis}", f"must be one of {', '.join(map(str, GLTF_WRAP_MODES))}")
                wrap[k] = GLTF_WRAP_MODES[mode]
        image_field = f"images[{source}]"
        image = self.element("images", source)
        described = image.get("uri") or image.get("name")
        label = f'{image_field} "{short_uri(described)}"' if isinstance(described, str) else image_field
        try:
            pixels_key, _ = self.textures.decoded(self.image_bytes(image, image_field))
        except ValueError as exc:
            self.fail(where, f"{label}: {exc}")
        return TextureUse(self.textures.texture(pixels_key, f"{self.json.path}: {label}", srgb, *wrap), uv_set, transform)

    def texture_transform(self, extensions, field, uv_set):
        """(texture coordinate set, 2x3 matrix) of KHR_texture_transform: T(offset) R(rotation)
        S(scale) applied to (u, v, 1), as the extension defines R = [[cos, sin], [-sin, cos]]."""
        read, where = self.json, f"{field}.KHR_texture_transform"
        spec = read.get(extensions, "KHR_texture_transform", field, kind=dict)
        offset = read.vector(spec, "offset", where, [0.0, 0.0], length=2)
        rotation = read.number(spec, "rotation", where, 0.0)
        scale = read.vector(spec, "scale", where, [1.0, 1.0], length=2)
        uv_set = int(read.number(spec, "texCoord", where, uv_set, whole=True, minimum=0, maximum=1))
        c, s = math.cos(rotation), math.sin(rotation)
        return uv_set, ((c * scale[0], s * scale[1], float(offset[0])), (-s * scale[0], c * scale[1], float(offset[1])))

