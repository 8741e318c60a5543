"""Render settings shared by the CLI, the viewer and the benchmark, and the table of modes."""
import difflib
import math
import numbers
from dataclasses import dataclass, fields

from ..core.constants import GRID_SIZES, MAX_INTERLEAVE, MAX_SHADOW_VIEWS, MAX_VOXEL_LEVELS
from ..core.errors import VctError

# Most diffuse bounces one change of the scene costs (converging, bounces 0, stops after as many).
MAX_BOUNCES = 64
# Largest exposure: the ACES curve overflows float32 once exposure x radiance passes ~1e19 and
# then shows the brightest pixels black.
MAX_EXPOSURE = 1e6
# Most jittered samples a frame averages (its screen passes run once per sample).
MAX_SAMPLES = 256
# The samples `vct render` takes by default: the fewest that bring the Cornell box's direct light
# within relMAE 0.0015 of the path tracer's box-filtered pixels (1: 0.0037, 4: 0.0029, 8: 0.0010).
HEADLESS_SAMPLES = 8
# Texels per side of a shadow view: the atlas holds 6 views a row, MAX_SHADOW_VIEWS in all,
# within the 16384 texels a side that OpenGL 4.5 drivers allow.
MIN_SHADOW_MAP_SIZE = 16
MAX_SHADOW_MAP_SIZE = 16384 // -(-MAX_SHADOW_VIEWS // 6)


@dataclass(frozen=True)
class Mode:
    """What a mode shows: the stage of the frame that makes its image ("gbuffer" views,
    "voxel_view", "cone_trace"), whether it is encoded data shown as stored (no
    exposure, curve or sRGB), and the terms a cone-traced image adds."""

    stage: str
    data: bool = False
    terms: tuple = ()

    def uses_voxels(self, lit_through_voxels):
        """Whether the image reads the voxels: voxel views and cone-traced terms; direct light
        alone only where emissive surfaces or the environment light the scene (their shadows
        are cones)."""
        return self.uses_radiance or (self.stage == "cone_trace" and lit_through_voxels)

    @property
    def uses_radiance(self):
        """Whether the image reads the voxels' light: voxel views, indirect light and AO."""
        return self.stage == "voxel_view" or any(term != "direct" for term in self.terms)


MODE_TABLE = {
    "gi": Mode("cone_trace", terms=("direct", "diffuse", "specular")),
    "direct": Mode("cone_trace", terms=("direct",)),
    "indirect": Mode("cone_trace", terms=("diffuse",)),
    "specular": Mode("cone_trace", terms=("specular",)),
    "ao": Mode("cone_trace", terms=("ao",)),
    "voxels": Mode("voxel_view"),
    "albedo": Mode("gbuffer", data=True),
    "normal": Mode("gbuffer", data=True),
    "depth": Mode("gbuffer", data=True),
    "voxel-normals": Mode("voxel_view", data=True),
    "voxel-albedo": Mode("voxel_view", data=True),
}
MODES = tuple(MODE_TABLE)
TONEMAPS = ("aces", "reinhard", "none")
DIFFUSE_CONE_SETS = ("six", "tiled")  # lib/cone.glsl: trace_diffuse


@dataclass(frozen=True)
class ImageTerms:
    """The terms a cone-traced image adds up, or AO alone."""

    direct: bool = False
    diffuse: bool = False
    specular: bool = False
    ao: bool = False


# What a setting of each declared type may hold, and how errors call it.
SETTING_TYPES = {str: str, bool: bool, int: numbers.Integral, float: numbers.Real}
TYPE_NAMES = {str: "a string", bool: "True or False", int: "a whole number (int)", float: "a number"}


@dataclass
class RenderSettings:
    mode: str = "gi"
    grid: int = 128                 # voxels per side, a power of two in 16..256
    clipmap_levels: int = None      # levels of grid^3 around the camera (engine/voxels/clipmap.py); 0: one grid; None: the scene's
    bounces: int = 0                # diffuse bounces through the voxels; 0 = iterate to convergence
    bounce_interleave: int = 4      # progressive (viewer), bounces 0: 1 in K voxels is updated each frame
    voxel_mip: int = 0              # mip level shown by the voxel views
    voxel_level: int = 0            # the clipmap level the voxel views show
    cone_step: float = 0.5          # march step as a fraction of the cone diameter
    cone_offset: float = 1.0        # cone start offset along the normal, in voxels
    diffuse_cones: str = "tiled"    # the diffuse and AO cones: "tiled" (the lecture's six, each as seven narrower ones; 14x the gather, refined at rest in progressive frames) or the lecture's "six"
    ao_distance: float = 1.0        # AO cones stop after this distance (world units)
    direct: bool = True             # gi: include direct light and emission
    indirect_diffuse: bool = True   # gi: include diffuse indirect light
    indirect_specular: bool = True  # gi: include specular indirect light
    exposure: float = 1.0
    tonemap: str = "aces"
    samples: int = 1                # jittered samples a pixel averages (a box filter; 1: the pixel centre)
    temporal_aa: bool = False       # temporal anti-aliasing: each frame one jittered sample blended into the last frames' (the viewer)
    shadow_map_size: int = 512      # texels per side of each shadow view (fixed per renderer)

    def validate(self):
        """The settings, each of its type (numpy numbers become Python's) and within its
        range; else VctError naming the setting."""
        for setting in fields(self):
            value = getattr(self, setting.name)
            if value is None and setting.default is None:
                continue  # the scene's own
            if not isinstance(value, SETTING_TYPES[setting.type]) or (setting.type is not bool and isinstance(value, bool)):
                raise VctError(f"must be {TYPE_NAMES[setting.type]}, got {value!r}", field=setting.name)
            if setting.type in (int, float):
                setattr(self, setting.name, setting.type(value))
        if self.mode not in MODE_TABLE:
            raise VctError(f'unknown mode "{self.mode}" (expected one of {", ".join(MODES)})', field="mode")
        if self.grid not in GRID_SIZES:
            raise VctError(f"grid must be a power of two from 16 to 256, got {self.grid}", field="grid")
        if self.clipmap_levels is not None and not 0 <= self.clipmap_levels <= MAX_VOXEL_LEVELS:
            raise VctError(f"must be None (the scene's), 0 (one grid) or a level count up to {MAX_VOXEL_LEVELS}, got {self.clipmap_levels}",
                           field="clipmap")
        if not 0 <= self.voxel_level < MAX_VOXEL_LEVELS:
            raise VctError(f"must be in 0..{MAX_VOXEL_LEVELS - 1}, got {self.voxel_level}", field="level")
        if not 0 <= self.bounces <= MAX_BOUNCES:
            raise VctError(f"must be 0 (converge) or a count up to {MAX_BOUNCES}, got {self.bounces}", field="bounces")
        if not 1 <= self.bounce_interleave <= MAX_INTERLEAVE:
            raise VctError(f"must be in 1..{MAX_INTERLEAVE}", field="bounce_interleave")
        if not 0 <= self.voxel_mip <= self.grid.bit_length() - 1:
            raise VctError(f"must be in 0..{self.grid.bit_length() - 1} for grid {self.grid}", field="mip")
        for name in ("cone_step", "cone_offset", "ao_distance", "exposure"):
            if not math.isfinite(getattr(self, name)):
                raise VctError("must be a finite number", field=name)
        if self.ao_distance <= 0:
            raise VctError("must be positive", field="ao_distance")
        if not 0.05 <= self.cone_step <= 2.0:
            raise VctError("must be in 0.05..2", field="cone_step")
        if self.cone_offset < 0:
            raise VctError("must not be negative", field="cone_offset")
        if not 1 <= self.samples <= MAX_SAMPLES:
            raise VctError(f"must be in 1..{MAX_SAMPLES}", field="samples")
        if self.diffuse_cones not in DIFFUSE_CONE_SETS:
            raise VctError(f"must be one of {', '.join(DIFFUSE_CONE_SETS)}, got {self.diffuse_cones!r}", field="diffuse_cones")
        if self.tonemap not in TONEMAPS:
            raise VctError(f'unknown tone mapper "{self.tonemap}"', field="tonemap")
        if not 0 < self.exposure <= MAX_EXPOSURE:
            raise VctError(f"must be positive and at most {MAX_EXPOSURE:g}", field="exposure")
        if not MIN_SHADOW_MAP_SIZE <= self.shadow_map_size <= MAX_SHADOW_MAP_SIZE:
            raise VctError(f"must be in {MIN_SHADOW_MAP_SIZE}..{MAX_SHADOW_MAP_SIZE}", field="shadow_map_size")
        return self

    @property
    def shown(self):
        return MODE_TABLE[self.mode]

    @property
    def temporal(self):
        """Whether frames blend into the frames before (temporal anti-aliasing; not a data view)."""
        return self.temporal_aa and not self.shown.data

    def image_terms(self):
        terms = self.shown.terms
        return ImageTerms(direct="direct" in terms and self.direct, diffuse="diffuse" in terms and self.indirect_diffuse,
                          specular="specular" in terms and self.indirect_specular, ao="ao" in terms)

    def cone_uniforms(self, diffuse_cones=None):
        """The uniforms of lib/cone.glsl, with diffuse cone set `diffuse_cones` (None: the settings')."""
        cone_set = diffuse_cones or self.diffuse_cones
        return dict(cone_step=float(self.cone_step), cone_offset=float(self.cone_offset), tiled_cones=cone_set == "tiled")

    def replace(self, **changes):
        known = {f.name for f in fields(self)}
        unknown = set(changes) - known
        if unknown:
            name = sorted(unknown)[0]
            near = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
            raise VctError(f'unknown setting "{name}"' + (f' (did you mean "{near[0]}"?)' if near else ""), field="settings")
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        values.update(changes)
        return RenderSettings(**values)
