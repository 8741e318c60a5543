"""Path-traced reference radiance for a vct scene, rendered with Mitsuba 3 (the renderer the
references in ../shared/reference came from), so any scene or variant can be checked the way
the Cornell box is:

    .venv/bin/pip install -e '.[reference]'
    .venv/bin/python tools/reference.py SCENE.json OUT.npy [--spp 1024] [--max-depth -1]
    .venv/bin/vct bench SCENE.json --reference OUT.npy      # or compare with `vct render --hdr`

Besides OUT.npy (linear float32 radiance (H, W, 3), row 0 at the top, each pixel integrated
over its footprint: box filter) it writes OUT.meta.json (tool version, Mitsuba variant,
integrator, spp, max depth, scene file and its SHA-256, date, render time, mean radiance and the
measured noise) and OUT.png (clip(radiance * --png-exposure, 0, 1), sRGB-encoded). The image is
rendered as two independent halves of spp/2 samples each (different seeds), in passes of
--pass-spp; OUT.npy is their mean and `halves_relMAE` = sum|A - B| / sum B between the halves,
the relative MAE of two independent renders at spp/2 (two at the full spp: about 1/sqrt(2) of
it). `--max-depth 2` gives direct light only (Mitsuba counts the camera ray and the emitter
hit), 3 direct + one bounce, -1 all bounces. `--variant llvm_ad_rgb` is several times faster
than the default scalar_rgb but needs a libLLVM that Dr.Jit can drive: Debian 12's LLVM 15
aborts ("Cannot select: fminimum"); libllvm19 works with
DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1. The passes' progress goes to
stderr (engine/core/progress.py): a bar on a terminal, else one line at the end; none with --quiet.

What is converted, and how
--------------------------
Geometry: every drawn mesh with its world transform, its own vertex normals as Mitsuba's
shading normals (spheres are shaded smooth, as the renderer draws them) and its texture
coordinates. Faces are one-sided by their winding (right-hand rule), as in the renderer.
Camera: perspective, vertical field of view, the scene's width and height. Environment: a
uniform sky is Mitsuba's `constant` emitter, a map its `envmap` with the same bitmap, `scale`
and `to_world` the rotation about +y (engine.scene.model.Environment's convention is Mitsuba's).
Lights: point
(W/sr, inverse square), spot (Mitsuba's fall-off between the inner and outer angles is linear in
angle, vct's smooth) and directional (W/m^2); `range` and `cast_shadows: false` are refused.

Materials. The scene format's BRDF (glsl/lib/brdf.glsl) is glTF 2.0's metallic-roughness model
with the lecture's lobe:

    f(l, v) = (1 - F(n.v)) c_diff / pi + F(v.h) D(h) G1(n.l) G1(n.v) / (4 n.l n.v)

with c_diff = (1 - m) k_d, Schlick's F of F0 = mix(`specular`, k_d, m) (zero where F0 = 0: no
specular layer), the normalized Blinn-Phong D = (s + 2) / (2 pi) (n.h)^s of s = 2 / r^4 - 2
(r clamped to >= 0.05) and Smith's G1 for the Beckmann lobe of alpha = r^2 (Walter et al.'s
rational fit). The reference renders exactly this f, as a Mitsuba BSDF written here
(`vct_layered`, a Python plugin that JIT variants compile like the built-in ones): eval and pdf
as above, sampling a mixture of cosine-weighted directions (the diffuse layer) and reflections
about half vectors drawn from D(h) (n.h) (the specular layer), picked in proportion to the
luminance of (1 - F(n.v)) c_diff and F(n.v). Materials without a specular layer are Mitsuba's
`diffuse`, which is the same f.

How the split follows glTF: glTF's Appendix B mixes the layers by Fresnel,
`mix(diffuse_brdf, specular_brdf, F)`; it evaluates F at v.h for each light direction, which
lets a smooth dielectric seen at grazing angles reflect more than it receives. The format
evaluates the diffuse layer's weight at the view direction, 1 - F(n.v), so that the two layers
never return more than arrives: in a white furnace (a sphere inside a closed box of walls that
emit and reflect nothing) a white dielectric returns the light it receives and a metal its
directional albedo, which tests/test_reference_tool.py renders. Mitsuba's plastics are not
used: they couple the layers through internal reflections, a different model.

Textures (materials from glTF/OBJ files, engine/scene/model.py `Material`): the base-colour texture
(sRGB-decoded) times the albedo factor becomes the float bitmap k_d; the metal-roughness
texture's G and B channels times the factors become per-texel roughness and metalness bitmaps;
the emissive texture (sRGB-decoded) times `emission` becomes the area emitter's radiance bitmap.
Texture coordinates go to Mitsuba unchanged: glTF's (0, 0) is the image's top-left and so is
Mitsuba's (the image's row 0 is at v = 0). Bitmaps are filtered bilinearly without mipmaps
(each pixel integrates its footprint by sampling) where the renderer filters trilinearly; wrap
modes map to repeat/mirror/clamp (Mitsuba has one mode for both axes: textures whose two modes
differ are refused where the texture coordinates leave [0, 1]). Alpha (alpha_mode MASK, and
BLEND drawn as MASK): the alpha (base-colour texture's alpha times `alpha`) is thresholded at
`alpha_cutoff` per texel into a 0/1 opacity bitmap read with nearest filtering inside a `mask`
BSDF, so the cut-out edges follow texel edges (exact for 0/1 alpha, within half a texel
otherwise); emission is cut out the same way, a surface cut out everywhere is dropped, and
scenes with masks are rendered with `volpath` (whose shadow rays pass through masks; `path`'s do
not). `double_sided` wraps the BSDF in `twosided`; emitters stay one-sided (front faces only).
Refused with one line naming the field: normal textures.
"""
import datetime
import hashlib
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import engine  # noqa: E402
from engine.app.cli import OneLineErrorParser, positive_int  # noqa: E402
from engine.core import transforms  # noqa: E402
from engine.core.progress import progress, set_quiet  # noqa: E402
from engine.scene.emitters import srgb_to_linear  # noqa: E402

TOOL_VERSION = 3  # 1: Lambertian only; 2: specular layer, textures, alpha masks, meta/png/halves; 3: glTF's layers
MIN_ROUGHNESS = 0.05  # glsl/lib/brdf.glsl clamps the roughness the same way
WRAP = {"REPEAT": "repeat", "MIRRORED_REPEAT": "mirror", "CLAMP_TO_EDGE": "clamp"}
mi = None  # the mitsuba module, imported by main() or use_mitsuba()


def use_mitsuba(variant="scalar_rgb"):
    """Import Mitsuba, select `variant` (the converter needs one to build transforms and bitmaps)
    and register the `vct_layered` BSDF."""
    global mi
    import mitsuba

    mitsuba.set_variant(variant)
    mi = mitsuba
    mitsuba.register_bsdf("vct_layered", _layered_bsdf_class())
    return mitsuba


def _layered_bsdf_class():
    """The Mitsuba BSDF of the scene format's layered model (the module docstring), for the
    variant selected: k_d `base_color` (a texture; times the mesh's "vertex_color" attribute
    where `vertex_colors`), `roughness` and `metalness` (float textures), `dielectric_f0` (a
    float)."""
    import drjit as dr

    class LayeredBSDF(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.base_color = props.get_unbounded_texture("base_color")
            self.roughness = props.get_texture("roughness")
            self.metalness = props.get_texture("metalness")
            self.dielectric_f0 = props.get("dielectric_f0")
            self.vertex_colors = props.get("vertex_colors", False)
            flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            self.m_components = [flags]
            self.m_flags = flags

        def layers(self, si, active):
            """(c_diff, F0, Blinn-Phong exponent s, Beckmann alpha) at the surface point."""
            k_d = self.base_color.eval(si, active)
            if self.vertex_colors:  # the mesh's COLOR_0 times the base colour
                k_d *= mi.Color3f(si.shape.eval_attribute_3("vertex_color", si, active))
            metalness = self.metalness.eval_1(si, active)
            roughness = dr.maximum(self.roughness.eval_1(si, active), MIN_ROUGHNESS)
            f0 = dr.lerp(mi.Color3f(self.dielectric_f0), k_d, metalness)
            return k_d * (1.0 - metalness), f0, 2.0 / dr.power(roughness, 4.0) - 2.0, roughness * roughness

        @staticmethod
        def fresnel(f0, cos_theta):  # Schlick's, zero without a specular layer (F0 = 0)
            f = f0 + (1.0 - f0) * dr.power(1.0 - dr.clip(cos_theta, 0.0, 1.0), 5.0)
            return dr.select(dr.any(f0 > 0.0), f, 0.0)

        @staticmethod
        def smith_g1(cos_theta, alpha):  # Walter et al.'s rational fit for the Beckmann lobe
            c = dr.clip(cos_theta, 1e-4, 1.0)
            a = c / (alpha * dr.sqrt(1.0 - c * c) + 1e-7)
            return dr.select(a >= 1.6, 1.0, (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a))

        @staticmethod
        def distribution(s, cos_h):  # normalized Blinn-Phong: int D (n.h) dw_h = 1
            return (s + 2.0) / (2.0 * dr.pi) * dr.power(dr.maximum(cos_h, 0.0), s)

        def specular_probability(self, si, active):
            c_diff, f0, _, _ = self.layers(si, active)
            f = self.fresnel(f0, mi.Frame3f.cos_theta(si.wi))
            specular, diffuse = mi.luminance(f), mi.luminance((1.0 - f) * c_diff)
            both = (specular > 0.0) & (diffuse > 0.0)
            return dr.select(both, dr.clip(specular / (specular + diffuse), 0.1, 0.9), dr.select(specular > 0.0, 1.0, 0.0))

        def eval(self, ctx, si, wo, active=True):
            """f(wo, si.wi) cos(wo)."""
            c_diff, f0, s, alpha = self.layers(si, active)
            cos_v, cos_l = mi.Frame3f.cos_theta(si.wi), mi.Frame3f.cos_theta(wo)
            h = dr.normalize(si.wi + wo)
            visibility = self.smith_g1(cos_l, alpha) * self.smith_g1(cos_v, alpha) / (
                4.0 * dr.maximum(cos_l, 1e-4) * dr.maximum(cos_v, 1e-4))
            f = ((1.0 - self.fresnel(f0, cos_v)) * c_diff / dr.pi
                 + self.fresnel(f0, dr.dot(si.wi, h)) * self.distribution(s, mi.Frame3f.cos_theta(h)) * visibility)
            return dr.select(active & (cos_v > 0.0) & (cos_l > 0.0), f * cos_l, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            _, _, s, _ = self.layers(si, active)
            cos_l = mi.Frame3f.cos_theta(wo)
            h = dr.normalize(si.wi + wo)
            cos_h = mi.Frame3f.cos_theta(h)
            specular = self.distribution(s, cos_h) * cos_h / (4.0 * dr.maximum(dr.dot(si.wi, h), 1e-6))
            p = self.specular_probability(si, active)
            pdf = p * specular + (1.0 - p) * dr.maximum(cos_l, 0.0) / dr.pi
            return dr.select(active & (mi.Frame3f.cos_theta(si.wi) > 0.0) & (cos_l > 0.0), pdf, 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            _, _, s, _ = self.layers(si, active)
            specular = sample1 < self.specular_probability(si, active)
            cos_h = dr.power(sample2.x, 1.0 / (s + 2.0))  # h drawn from D(h) (n.h)
            sin_h = dr.sqrt(dr.maximum(1.0 - cos_h * cos_h, 0.0))
            phi = 2.0 * dr.pi * sample2.y
            h = mi.Vector3f(sin_h * dr.cos(phi), sin_h * dr.sin(phi), cos_h)
            reflected = 2.0 * dr.dot(si.wi, h) * h - si.wi
            bs = mi.BSDFSample3f()
            bs.wo = dr.select(specular, reflected, mi.warp.square_to_cosine_hemisphere(sample2))
            bs.pdf = self.pdf(ctx, si, bs.wo, active)
            bs.eta = 1.0
            bs.sampled_type = dr.select(specular, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                                        mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
            bs.sampled_component = mi.UInt32(0)
            weight = self.eval(ctx, si, bs.wo, active) / dr.maximum(bs.pdf, 1e-12)
            return bs, dr.select(active & (bs.pdf > 0.0), weight, 0.0)

        def traverse(self, callback):
            pass

        def to_string(self):
            return "LayeredBSDF[the scene format's glTF layers]"

    return LayeredBSDF


class ReferenceError_(engine.VctError):
    """A scene the reference cannot render as the renderer would (one line naming the field)."""


# ---- meshes -------------------------------------------------------------------------------

def write_ply(path, positions, indices, normals=None, texcoords=None, colors=None):
    """Binary PLY that Mitsuba's `ply` shape reads: x y z [nx ny nz] [u v] [r g b] (the vertex
    colours Mitsuba names "vertex_color"), triangles."""
    columns, names = [np.asarray(positions, np.float32)], ["x", "y", "z"]
    for values, value_names in ((normals, ["nx", "ny", "nz"]), (texcoords, ["u", "v"]), (colors, ["r", "g", "b"])):
        if values is not None:
            columns.append(np.asarray(values, np.float32))
            names += value_names
    vertices = np.ascontiguousarray(np.hstack(columns), dtype="<f4")
    faces = np.zeros(len(indices), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"] = 3
    faces["i"] = np.asarray(indices).reshape(-1, 3)
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(vertices)}\n" + "".join(f"property float {n}\n" for n in names) +
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    Path(path).write_bytes(header.encode("ascii") + vertices.tobytes() + faces.tobytes())


def read_ply(path):
    """(vertex table (V, columns) float32, property names, triangles) of a PLY made by write_ply."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    names = [line.split()[2] for line in lines if line.startswith("property float")]
    count = int(next(line for line in lines if line.startswith("element vertex")).split()[2])
    faces = int(next(line for line in lines if line.startswith("element face")).split()[2])
    vertices = np.frombuffer(data, "<f4", count * len(names), end).reshape(count, len(names))
    triangles = np.frombuffer(data, [("n", "u1"), ("i", "<i4", (3,))], faces, end + vertices.nbytes)["i"]
    return vertices, names, triangles


# ---- the converter ------------------------------------------------------------------------

class Converter:
    """Builds the Mitsuba scene dict of a vct scene; meshes are written as PLY into `mesh_dir`."""

    def __init__(self, scene, mesh_dir):
        self.scene = scene
        self.mesh_dir = Path(mesh_dir)
        self.masked = False

    def fail(self, field, message):
        raise ReferenceError_(message, source=self.scene.source, field=field)

    # -- textures

    def bitmap(self, array, wrap="repeat", nearest=False, uv_transform=None):
        """A Mitsuba bitmap texture of linear float values (H, W, C), row 0 at the image's top,
        read through the 2x3 texture coordinate transform `uv_transform` (identity: None)."""
        array = np.ascontiguousarray(array, np.float32)
        if array.ndim == 2:
            array = array[..., None]
        texture = {"type": "bitmap", "bitmap": mi.Bitmap(array), "raw": True,
                   "filter_type": "nearest" if nearest else "bilinear", "wrap_mode": wrap}
        if uv_transform is not None:
            texture["to_uv"] = mi.ScalarTransform3f(np.vstack([np.asarray(uv_transform, np.float64), [0.0, 0.0, 1.0]]))
        return texture

    def colour(self, value, texture=None, wrap="repeat", uv_transform=None):
        """rgb(value), or a float bitmap (texture times value) where a texture is given or a value
        exceeds 1 (Mitsuba refuses reflectances above 1 in rgb, not in float bitmaps)."""
        value = np.asarray(value, np.float64)
        if texture is None:
            if np.all(value <= 1.0):
                return {"type": "rgb", "value": [float(v) for v in value]}
            return self.bitmap(value.reshape(1, 1, 3))
        return self.bitmap(texture * value, wrap, uv_transform=uv_transform)

    def uv_transform(self, material, texture_field, field):
        """The texture's coordinate transform for a bitmap; textures on the second coordinate
        set are refused (Mitsuba's meshes hold one)."""
        if material.uv_sets.get(texture_field, 0) != 0:
            self.fail(f"{field}.{texture_field}", "reads TEXCOORD_1: Mitsuba's meshes hold one set of texture coordinates")
        return material.uv_transform(texture_field)

    @staticmethod
    def rgb_of(texture):
        """Linear RGB (H, W, 3) of a Texture: sRGB-decoded where it is colour; grey replicated."""
        image = texture.image.astype(np.float64) / 255.0
        rgb = image[..., :3] if image.shape[2] >= 3 else np.repeat(image[..., :1], 3, axis=2)
        return srgb_to_linear(rgb) if texture.srgb else rgb

    @staticmethod
    def alpha_of(texture):
        """The alpha channel (H, W) of a Texture (linear), or None where it has none."""
        if texture.image.shape[2] in (2, 4):
            return texture.image[..., -1].astype(np.float64) / 255.0
        return None

    def wrap_of(self, texture, mesh, field):
        if texture.wrap_s != texture.wrap_t:
            uv = mesh.texcoords
            if uv is not None and (uv.min() < 0.0 or uv.max() > 1.0):
                self.fail(field, f"wrap modes {texture.wrap_s} (u) and {texture.wrap_t} (v) differ and the texture "
                                 "coordinates leave [0, 1]: Mitsuba's bitmap has one wrap mode for both axes")
        return WRAP[texture.wrap_s]

    # -- materials

    def opacity(self, material, mesh, field):
        """None (opaque), 0.0 (cut out everywhere) or (H, W) 0/1 opacity of the texels."""
        if not material.alpha_tested:
            return None
        alpha = np.full((1, 1), float(material.alpha))
        if material.base_color_texture is not None and self.alpha_of(material.base_color_texture) is not None:
            alpha = self.alpha_of(material.base_color_texture) * material.alpha
        keep = (alpha >= material.alpha_cutoff).astype(np.float32)
        if keep.all():
            return None
        if not keep.any():
            return 0.0
        if alpha.shape == (1, 1):
            return None if keep[0, 0] else 0.0
        return keep

    def bsdf(self, material, mesh, field):
        """The Mitsuba BSDF dict of a vct Material (see the module docstring)."""
        if material.normal_texture is not None:
            self.fail(f"{field}.normal_texture", "normal textures are not converted (Mitsuba's normalmap builds its "
                                                 "tangent frame differently); give the part a scene material")
        base = material.base_color_texture
        wrap = self.wrap_of(base, mesh, f"{field}.base_color_texture") if base is not None else "repeat"
        k_d = self.colour(material.albedo, self.rgb_of(base) if base is not None else None, wrap,
                          self.uv_transform(material, "base_color_texture", field))
        roughness, metalness = float(material.roughness), float(material.metalness)
        mr = material.metallic_roughness_texture
        if mr is not None:  # per texel: G x roughness, B x metalness
            channels = self.rgb_of(mr)
            mr_wrap = self.wrap_of(mr, mesh, f"{field}.metallic_roughness_texture")
            mr_uv = self.uv_transform(material, "metallic_roughness_texture", field)
            roughness = self.bitmap(roughness * channels[..., 1], mr_wrap, uv_transform=mr_uv)
            metalness = self.bitmap(metalness * channels[..., 2], mr_wrap, uv_transform=mr_uv) if metalness > 0 else 0.0
        if material.specular == 0 and metalness == 0 and mesh.colors is None:  # no specular layer: Lambert alone
            return {"type": "diffuse", "reflectance": k_d}
        return {"type": "vct_layered", "base_color": k_d, "roughness": roughness, "metalness": metalness,
                "dielectric_f0": float(material.specular), "vertex_colors": mesh.colors is not None}

    def surface(self, material, mesh, field):
        """(bsdf, emitter) dicts of a drawn part, or None where the part is cut out everywhere."""
        keep = self.opacity(material, mesh, field)
        if isinstance(keep, float):
            return None
        bsdf = self.bsdf(material, mesh, field)
        if material.double_sided:
            bsdf = {"type": "twosided", "bsdf": bsdf}
        if keep is not None:
            bsdf = {"type": "mask", "opacity": self.bitmap(keep, self.wrap_of(material.base_color_texture, mesh, field), nearest=True,
                                                          uv_transform=material.uv_transform("base_color_texture")),
                    "bsdf": bsdf}
            self.masked = True
        emitter = None
        emission = np.asarray(material.emission, np.float64)
        if np.any(emission > 0):
            texture = material.emissive_texture
            if texture is None and keep is None:
                emitter = {"type": "area", "radiance": {"type": "rgb", "value": [float(v) for v in emission]}}
            else:
                radiance = self.rgb_of(texture) * emission if texture is not None else emission.reshape(1, 1, 3)
                wrap = self.wrap_of(texture, mesh, f"{field}.emissive_texture") if texture is not None else "repeat"
                if keep is not None:  # cut out where the surface is: both on the finer of the two grids
                    shape = max(radiance.shape[:2], keep.shape, key=lambda s: s[0] * s[1])
                    radiance = _resample(radiance, shape) * _resample(keep[..., None], shape)
                    wrap = self.wrap_of(material.base_color_texture, mesh, field)
                uv = material.uv_transform("emissive_texture" if texture is not None else "base_color_texture")
                emitter = {"type": "area", "radiance": self.bitmap(radiance, wrap, uv_transform=uv)}
        return bsdf, emitter

    # -- the scene

    def scene_dict(self, spp, max_depth, sampler="independent"):
        scene = self.scene
        camera = scene.camera
        to_world = mi.ScalarTransform4f.look_at(origin=[float(v) for v in camera.position],
                                               target=[float(v) for v in camera.look_at], up=[float(v) for v in camera.up])
        sensor = {
            "type": "perspective", "fov": float(camera.vertical_fov_deg), "fov_axis": "y", "to_world": to_world,
            "film": {"type": "hdrfilm", "width": int(camera.width), "height": int(camera.height),
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": sampler, "sample_count": int(spp)},
        }
        if camera.projection == "orthographic":  # its view spans [-1, 1]^2, scaled to the half-extents
            half_width = camera.half_height * camera.width / camera.height
            del sensor["fov"], sensor["fov_axis"]
            sensor.update(type="orthographic", to_world=to_world @ mi.ScalarTransform4f.scale([half_width, camera.half_height, 1.0]))
        result = {"type": "scene", "sensor": sensor}
        for k, (node, world) in enumerate(scene.drawables()):
            material = node.material
            field = f'objects "{node.name}" material "{material.name}"'
            surface = self.surface(material, node.mesh, field)
            if surface is None:
                continue
            bsdf, emitter = surface
            path = self.mesh_dir / f"mesh{k}.ply"
            self.write_mesh(path, node.mesh, world, needs_texcoords=_has_textures(material), field=field)
            shape = {"type": "ply", "filename": str(path), "face_normals": False, "bsdf": bsdf}
            if emitter is not None:
                shape["emitter"] = emitter
            result[f"shape{k}"] = shape
        for k, (node, light) in enumerate(scene.lights()):
            field = f'lights "{node.name}"'
            if light.range > 0:
                self.fail(f"{field}.range", "the reference has no light range (inverse square only)")
            if not light.cast_shadows:
                self.fail(f"{field}.cast_shadows", "the reference's lights always cast shadows")
            if light.type == "point":
                emitter = {"type": "point", "position": [float(v) for v in light.position],
                           "intensity": {"type": "rgb", "value": [float(v) for v in light.intensity]}}
            elif light.type == "spot":
                # vct's spot falls off smoothly between the inner and outer angles, Mitsuba's linearly.
                up = [0, 1, 0] if abs(light.direction[1]) < 0.99 else [1, 0, 0]
                emitter = {"type": "spot", "intensity": {"type": "rgb", "value": [float(v) for v in light.intensity]},
                           "cutoff_angle": float(light.outer_angle_deg), "beam_width": float(light.inner_angle_deg),
                           "to_world": mi.ScalarTransform4f.look_at(origin=[float(v) for v in light.position],
                                                                    target=[float(v) for v in light.position + light.direction],
                                                                    up=up)}
            else:
                emitter = {"type": "directional", "direction": [float(v) for v in light.direction],
                           "irradiance": {"type": "rgb", "value": [float(v) for v in light.intensity]}}
            result[f"light{k}"] = emitter
        environment = scene.environment
        if environment is not None:  # the same convention (engine.scene.model.Environment): no conversion of the map
            if environment.image is None:
                result["environment"] = {"type": "constant", "radiance": {
                    "type": "rgb", "value": [float(v) * environment.scale for v in environment.radiance]}}
            else:
                result["environment"] = {"type": "envmap", "bitmap": mi.Bitmap(np.array(environment.image, np.float32)),
                                         "scale": float(environment.scale),
                                         "to_world": mi.ScalarTransform4f.rotate([0, 1, 0], float(environment.rotation_y_deg))}
        # Shadow rays of `path` stop at any surface; `volpath` lets them through masks' holes.
        result["integrator"] = {"type": "volpath" if self.masked else "path", "max_depth": int(max_depth)}
        return result

    def write_mesh(self, path, mesh, world, needs_texcoords, field):
        positions = transforms.transform_points(world, mesh.positions)
        normal_matrix = np.linalg.inv(world[:3, :3]).T
        normals = np.asarray(mesh.normals, np.float64) @ normal_matrix.T
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
        indices = np.asarray(mesh.indices).reshape(-1, 3)
        if np.linalg.det(world[:3, :3]) < 0:  # a mirroring transform: keep the front faces in front
            indices = indices[:, ::-1]
        if needs_texcoords and mesh.texcoords is None:
            self.fail(field, "the material has textures but the mesh has no texture coordinates")
        write_ply(path, positions, indices, normals, mesh.texcoords, mesh.colors)


def _has_textures(material):
    return bool(material.textures())


def _resample(image, shape):
    """Nearest-neighbour resampling of (H, W, C) to shape (h, w), by texel centres."""
    if image.shape[:2] == tuple(shape):
        return image
    rows = np.minimum((np.arange(shape[0]) + 0.5) * image.shape[0] / shape[0], image.shape[0] - 1).astype(int)
    cols = np.minimum((np.arange(shape[1]) + 0.5) * image.shape[1] / shape[1], image.shape[1] - 1).astype(int)
    return image[rows][:, cols]


def scene_dict(scene, spp, max_depth, mesh_dir, sampler="independent"):
    """The Mitsuba scene dict of a vct scene (mitsuba must be imported: use_mitsuba())."""
    return Converter(scene, mesh_dir).scene_dict(spp, max_depth, sampler)


# ---- rendering and output -------------------------------------------------------------------

def rel_mae(image, reference):
    return float(np.abs(image.astype(np.float64) - reference).sum() / np.asarray(reference, np.float64).sum())


def render(scene, spp, max_depth, seed=0, pass_spp=64, sampler="independent", pass_done=None):
    """(mean image, half A, half B, integrator): two independent halves of spp/2 samples each,
    in passes of pass_spp samples with distinct seeds; `pass_done()` is called after each pass."""
    halves = []
    with tempfile.TemporaryDirectory() as mesh_dir:
        converted = scene_dict(scene, pass_spp, max_depth, mesh_dir, sampler)
        loaded = mi.load_dict(converted)
        passes = spp // 2 // pass_spp
        for half in range(2):
            total = None
            for k in range(passes):
                pass_seed = (seed * 2 + half) * 100_003 + k
                image = np.array(mi.render(loaded, spp=pass_spp, seed=pass_seed), dtype=np.float64)[..., :3]
                total = image if total is None else total + image
                if pass_done:
                    pass_done()
            halves.append(total / passes)
    return (halves[0] + halves[1]) / 2.0, halves[0], halves[1], converted["integrator"]["type"]


def emitter_pixels(scene, spp=16):
    """Boolean (H, W): pixels where the camera sees an emitter directly (in any part of the footprint)."""
    with tempfile.TemporaryDirectory() as mesh_dir:
        loaded = mi.load_dict(scene_dict(scene, spp, 1, mesh_dir))
        return np.array(mi.render(loaded, spp=spp, seed=1), dtype=np.float64)[..., :3].max(axis=2) > 0


def preview(image, exposure):
    """uint8 sRGB of clip(radiance * exposure, 0, 1)."""
    c = np.clip(image * exposure, 0.0, 1.0)
    c = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.round(c * 255.0).astype(np.uint8)


def git_commit():
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, timeout=10)
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "tools/reference.py", "engine"],
                               capture_output=True, text=True, timeout=10)
        return out.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "") if out.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        return None


def _display_path(path):
    path = Path(path).resolve()
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)


def main(argv=None):
    parser = OneLineErrorParser(prog="reference.py", description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("out", help="output .npy (linear float32 radiance, row 0 at the top); .meta.json and .png beside it")
    parser.add_argument("--spp", type=positive_int, default=1024, help="samples per pixel in all (two halves of spp/2)")
    parser.add_argument("--max-depth", type=int, default=-1, help="-1: all bounces; 2: direct only; 3: + one bounce")
    parser.add_argument("--pass-spp", type=positive_int, default=64, help="samples per pixel of one render call")
    parser.add_argument("--seed", type=int, default=0, help="seeds of the passes derive from it (0..9999)")
    parser.add_argument("--sampler", default="independent", choices=["independent", "stratified", "multijitter"])
    parser.add_argument("--variant", default="scalar_rgb", choices=["scalar_rgb", "llvm_ad_rgb"])
    parser.add_argument("--png-exposure", type=float, default=0.6, help="preview: clip(radiance * exposure, 0, 1), sRGB")
    parser.add_argument("--note", default=None, help="a line stored in the meta (what the scene tests)")
    parser.add_argument("--width", type=positive_int, help="image width (default: the scene camera's)")
    parser.add_argument("--height", type=positive_int, help="image height (default: the scene camera's)")
    parser.add_argument("--quiet", action="store_true",
                        help="no progress (else a bar on a terminal, one line on stderr at the end otherwise)")
    args = parser.parse_args(argv)
    set_quiet(args.quiet)
    if args.max_depth == 0 or args.max_depth < -1:
        parser.error("argument --max-depth: must be -1 (all bounces) or at least 1")
    if args.spp % (2 * args.pass_spp):
        parser.error(f"argument --spp: must be a multiple of 2 x --pass-spp = {2 * args.pass_spp} (two halves of whole passes)")
    if args.sampler != "independent" and round(args.pass_spp ** 0.5) ** 2 != args.pass_spp:
        parser.error(f"argument --pass-spp: the {args.sampler} sampler needs a perfect square, got {args.pass_spp}")
    if not 0 <= args.seed < 10000:
        parser.error("argument --seed: must be in 0..9999")
    out = Path(args.out)
    if out.suffix != ".npy":
        parser.error(f"argument out: must end in .npy, got {args.out!r}")
    if not out.parent.is_dir():
        parser.error(f"argument out: directory {str(out.parent)!r} does not exist")
    try:
        use_mitsuba(args.variant)
    except ImportError:
        print("reference.py: error: mitsuba is not installed (pip install -e '.[reference]')", file=sys.stderr)
        return 2
    try:
        scene = engine.load_scene(args.scene)
        scene.camera.width = args.width or scene.camera.width
        scene.camera.height = args.height or scene.camera.height
        with tempfile.TemporaryDirectory() as mesh_dir:  # convert first: bad input fails before rendering
            scene_dict(scene, args.pass_spp, args.max_depth, mesh_dir, args.sampler)
        commit = git_commit()  # before rendering: the code that renders is the code of this commit
        start = time.time()
        with progress(args.spp // args.pass_spp, "reference", "pass") as rendering:
            image, a, b, integrator = render(scene, args.spp, args.max_depth, args.seed, args.pass_spp, args.sampler,
                                             rendering.update)
        seconds = time.time() - start
        image = image.astype(np.float32)
        halves_mae = rel_mae(a, b)
        emitters = emitter_pixels(scene)
        lit = ~emitters
        halves_mae_lit = rel_mae(a[lit], b[lit]) if lit.any() and b[lit].sum() > 0 else None
        halves_rmse = float(np.sqrt(((a - b) ** 2).sum() / (b ** 2).sum()))
        scene_path = Path(args.scene)
        meta = {
            "scene": _display_path(scene_path),
            "scene_sha256": hashlib.sha256(scene_path.read_bytes()).hexdigest(),
            "note": args.note,
            "tool": "tools/reference.py", "tool_version": TOOL_VERSION, "git_commit": commit,
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "renderer": f"mitsuba {mi.__version__} ({args.variant})",
            "integrator": integrator,
            "max_depth": args.max_depth, "rr_depth": 5,
            "spp": args.spp, "spp_per_pass": args.pass_spp, "sampler": args.sampler, "rfilter": "box", "seed": args.seed,
            "render_seconds": round(seconds, 1),
            "convergence": {
                "halves_relMAE": round(halves_mae, 6),
                "halves_relRMSE_global": round(halves_rmse, 6),
                "halves_spp": args.spp // 2,
                "est_two_full_renders_relMAE": round(halves_mae / 2 ** 0.5, 6),
                "est_vs_converged_relMAE": round(halves_mae / 2, 6),
                "emitter_pixels": int(emitters.sum()),
                "halves_relMAE_without_emitter_pixels": None if halves_mae_lit is None else round(halves_mae_lit, 6),
                "definition": "relMAE(A, B) = sum|A - B| / sum B over pixels and channels; A, B: independent "
                              "renders of spp/2 each (different seeds); the reference is their mean; "
                              "without_emitter_pixels: over the pixels where no emitter is seen directly",
            },
            "png_exposure": args.png_exposure,
            "png_encoding": "clip(radiance*exposure, 0, 1) -> sRGB",
            "mean_radiance_rgb": [float(v) for v in image.reshape(-1, 3).mean(axis=0)],
            "shape": list(image.shape), "dtype": "float32", "row0": "top",
        }
        text = json.dumps(meta, indent=1) + "\n"
        engine.formats.output.write_files([(out, engine.formats.output.npy_writer(image)),
                                   (out.with_suffix(".png"), engine.formats.output.png_writer(preview(image, args.png_exposure))),
                                   (out.with_suffix(".meta.json"), lambda f: f.write(text.encode()))])
    except engine.VctError as exc:
        print(f"reference.py: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {out} ({image.shape[1]}x{image.shape[0]}, {args.spp} spp, max depth {args.max_depth}, {args.variant}, "
          f"{seconds:.0f} s), halves relMAE {halves_mae:.4f} ({halves_mae_lit if halves_mae_lit is None else round(halves_mae_lit, 4)} "
          f"without the {int(emitters.sum())} emitter pixels), mean radiance {np.round(meta['mean_radiance_rgb'], 4).tolist()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
