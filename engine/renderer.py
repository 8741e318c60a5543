"""The renderer: wires the passes together in plain order and returns linear HDR radiance.

    scene = engine.load_scene("scenes/cornell_box.json")
    with engine.Renderer(256, 256) as r:
        radiance = r.render(scene, mode="direct")    # float32 (H, W, 3), row 0 at the top
        r.save_png("out.png")                          # tone-mapped with the settings' curve
"""
import functools
import time
from contextlib import contextmanager

import numpy as np

from .errors import VctError
from .gl import create_headless_context
from .output import save_png
from .passes.bounce import BouncePass
from .passes.cone_trace import ConeTracePass
from .passes.gbuffer import GBufferPass
from .passes.gbuffer_view import GBufferViewPass
from .passes.lighting import LightingPass
from .passes.shadow import ShadowPass
from .passes.tonemap import TonemapPass
from .passes.voxel_view import VoxelViewPass
from .passes.voxelize import VoxelizePass
from .scene_gpu import SceneGeometry
from .settings import DATA_MODES, GBUFFER_VIEWS, VOXEL_MODES, VOXEL_VIEWS, RenderSettings
from .shaders import GLSL_ROOT, ProgramLibrary

NEAR_PLANE = 0.01


def _current(method):
    """Make the renderer's context current around a public method: several renderers (and
    their contexts) may live in one process."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        if self._context_entered:  # nested call: already current
            return method(self, *args, **kwargs)
        self._context_entered = True
        try:
            with self.ctx:
                return method(self, *args, **kwargs)
        finally:
            self._context_entered = False
    return wrapper


class Renderer:
    def __init__(self, width, height, settings=None, ctx=None, glsl_root=GLSL_ROOT):
        self.settings = (settings or RenderSettings()).validate()
        self.size = (int(width), int(height))
        if self.size[0] <= 0 or self.size[1] <= 0:
            raise VctError(f"image size must be positive, got {self.size[0]}x{self.size[1]}", field="size")
        self._owns_context = ctx is None
        self._context_entered = False
        self.ctx = ctx or create_headless_context()
        self._check_size(self.size)
        self.programs = ProgramLibrary(self.ctx, glsl_root)
        self.geometry = SceneGeometry(self.ctx)
        self.measure = False  # when True, each pass is timed with ctx.finish() + wall clock
        # When True (the viewer), bounces=0 runs one bounce per frame seeded by the previous
        # frame's voxel radiance instead of iterating to convergence within the frame.
        self.feedback = False
        self.timings = {}
        self._passes = []
        try:
            self.shadow = self._add(ShadowPass(self.ctx, self.programs, self.geometry, self.settings.shadow_map_size))
            self.gbuffer = self._add(GBufferPass(self.ctx, self.programs, self.geometry, self.size))
            self.lighting = self._add(LightingPass(self.ctx, self.programs, self.size))
            self.gbuffer_view = self._add(GBufferViewPass(self.ctx, self.programs, self.size))
            self.voxelize = self._add(VoxelizePass(self.ctx, self.programs, self.geometry))
            self.bounce = self._add(BouncePass(self.ctx, self.programs))
            self.cone_trace = self._add(ConeTracePass(self.ctx, self.programs, self.size))
            self.voxel_view = self._add(VoxelViewPass(self.ctx, self.programs, self.size))
            self.tonemap = self._add(TonemapPass(self.ctx, self.programs, self.size))
        except Exception:
            self.close()
            raise
        self.output = None  # the ScreenTarget holding the last frame's HDR result
        self.frame_settings = self.settings  # the settings the last frame used
        self._history_set = None  # face set holding the last frame's voxel radiance (feedback)
        self.bounce_iterations = 0
        self._frame = 0  # frames rendered with voxels, for the bounce interleave

    def _add(self, render_pass):
        self._passes.append(render_pass)
        return render_pass

    def _check_size(self, size):
        limit = min(self.ctx.info["GL_MAX_TEXTURE_SIZE"], *self.ctx.info["GL_MAX_VIEWPORT_DIMS"])
        if max(size) > limit:
            if self._owns_context:
                self.ctx.release()
            raise VctError(f"image size {size[0]}x{size[1]} exceeds the driver's limit of {limit} pixels per side",
                           field="size")

    @_current
    def resize(self, width, height):
        """Follow a new output size (all screen-space targets are recreated)."""
        self._check_size((int(width), int(height)))
        self.size = (max(1, int(width)), max(1, int(height)))
        for render_pass in (self.gbuffer, self.lighting, self.gbuffer_view, self.cone_trace, self.voxel_view, self.tonemap):
            render_pass.resize(self.size)

    @_current
    def voxels(self, name="radiance", level=0):
        """A voxel volume of the last frame as float32 (n, n, n, 4), indexed [z, y, x]:
        "radiance" (emission + direct light, premultiplied, a = opacity), "normal" (mean normal,
        its length the coherence), "albedo"; levels above 0 come from hardware mipmaps."""
        volume = {"radiance": self.voxelize.radiance, "normal": self.voxelize.normal, "albedo": self.voxelize.albedo}[name]
        if level > 0:
            volume.build_mipmaps()
        return self.voxelize.read_volume(volume, level)

    @_current
    def reload_shaders(self):
        """Rebuild the programs whose GLSL files changed; a failing one keeps its last good
        build. Returns (rebuilt count, [ShaderError]) for this poll."""
        return self.programs.reload_changed()

    # -- frame ---------------------------------------------------------------------------

    @contextmanager
    def timed(self, name):
        if not self.measure:
            yield
            return
        self.ctx.finish()
        start = time.perf_counter()
        yield
        self.ctx.finish()
        self.timings[name] = self.timings.get(name, 0.0) + (time.perf_counter() - start) * 1000.0

    def camera_matrices(self, camera, bounds):
        """View, projection and far plane (past the farthest corner of the scene's bounds)."""
        lo, hi = bounds
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        far = float(np.max(np.linalg.norm(corners - camera.position, axis=1))) * 1.1 + 1.0
        view = camera.view_matrix()
        projection = camera.projection_matrix(self.size[0] / self.size[1], NEAR_PLANE, far)
        return view, projection, far

    @_current
    def render_frame(self, scene, settings=None):
        """Render one frame on the GPU; `self.output` holds the HDR result. Returns it."""
        s = (settings or self.settings).validate()
        self.frame_settings = s
        self.timings = {}
        self.geometry.draw_calls = 0
        camera = scene.camera
        view, projection, far = self.camera_matrices(camera, scene.bounds())
        with self.timed("shadow"):
            self.shadow.update(scene)
        with self.timed("gbuffer"):
            self.gbuffer.render(scene, projection @ view)
        self.gbuffer.bind()
        if s.mode in GBUFFER_VIEWS:
            with self.timed("gbuffer_view"):
                forward = camera.look_at - camera.position
                self.gbuffer_view.render(s.mode, camera.position, forward / np.linalg.norm(forward), far)
            self.output = self.gbuffer_view.target
            return self.output
        self.shadow.bind(self.lighting.program, self.voxelize.program)
        with self.timed("lighting"):
            self.lighting.render(camera.position)
        self.output = self.lighting.target
        if s.mode in VOXEL_VIEWS:
            self.output = self._voxel_view(scene, s, projection @ view, camera.position)
        elif s.mode in VOXEL_MODES:
            self.output = self._cone_trace(scene, s, camera.position)
        return self.output

    def _voxel_view(self, scene, s, view_projection, camera_position):
        with self.timed("voxelize"):
            self.voxelize.run(scene, s.grid)
        shown = {"voxels": self.voxelize.radiance, "voxel-normals": self.voxelize.normal,
                 "voxel-albedo": self.voxelize.albedo}[s.mode]
        with self.timed("voxel_view"):
            shown.build_mipmaps()
            self.voxel_view.render(s.mode, shown, s.voxel_mip, self.voxelize.uniforms(), view_projection, camera_position)
        return self.voxel_view.target

    def _cone_trace(self, scene, s, camera_position):
        face_set = self.build_voxels(scene, s)
        with self.timed("cone_trace"):
            self.cone_trace.render(self.voxelize.uniforms(), self.cone_uniforms(s), self.voxelize.face_sets[face_set],
                                   self.lighting.target.texture, camera_position, ao=s.mode == "ao",
                                   direct=s.mode == "gi" and s.direct,
                                   diffuse=s.mode == "indirect" or (s.mode == "gi" and s.indirect_diffuse),
                                   specular=s.mode == "specular" or (s.mode == "gi" and s.indirect_specular),
                                   ao_distance=s.ao_distance)
        return self.cone_trace.target

    def cone_uniforms(self, s):
        return dict(cone_step=float(s.cone_step), cone_offset=float(s.cone_offset),
                    voxel_max_mip=float(self.voxelize.mip_count - 1))

    def build_voxels(self, scene, s):
        """Voxelize, mipmap and bounce; returns the face set (index) cones should read."""
        history = self._history_set if (self.feedback and s.bounces == 0 and s.grid == self.voxelize.grid) else None
        target = 0 if history is None else 1 - history
        with self.timed("voxelize"):
            self.voxelize.run(scene, s.grid, target)
        source = history if history is not None else target
        if source == target:  # cones or the first bounce read the freshly voxelized set
            with self.timed("mipmap"):
                self.voxelize.mipmap_faces(target)
        cone_uniforms = self.cone_uniforms(s)
        if s.bounces == 0 and not self.feedback:
            with self.timed("bounces"):
                source, iterations = self.bounce.converge(self.voxelize, cone_uniforms, source)
        else:  # feedback: one (amortized) bounce per frame; else bounces - 1 re-injections
            iterations = 1 if s.bounces == 0 else s.bounces - 1
            interleave = s.bounce_interleave if s.bounces == 0 else 1
            for _ in range(iterations):
                with self.timed("bounces"):
                    source = self.bounce.run(self.voxelize, cone_uniforms, source, interleave, self._frame)
                with self.timed("mipmap"):
                    self.voxelize.mipmap_faces(source)
        self.bounce_iterations = iterations
        self._history_set = source
        self._frame += 1
        return source

    @_current
    def render(self, scene, mode=None, **changes):
        """Render and return linear radiance, float32 (H, W, 3), row 0 at the top. `mode` and
        other settings given here apply to this frame only."""
        settings = self.settings.replace(**changes) if changes else self.settings
        if mode is not None:
            settings = settings.replace(mode=mode)
        self.render_frame(scene, settings)
        return self.radiance()

    @_current
    def radiance(self):
        """The last frame's linear radiance (or encoded data view), float32 (H, W, 3), row 0 at the top."""
        return self.output.read()[..., :3].copy()

    @_current
    def display_target(self):
        """Tone-map the last frame on the GPU; returns the 8-bit ScreenTarget (for a window)."""
        s = self.frame_settings
        with self.timed("tonemap"):
            if s.mode in DATA_MODES:  # encoded data: shown as stored, no curve, no sRGB
                self.tonemap.render(self.output.texture, 1.0, "none", encode_srgb=False)
            else:
                self.tonemap.render(self.output.texture, s.exposure, s.tonemap)
        return self.tonemap.target

    @_current
    def tonemapped(self):
        """The last frame as display pixels, uint8 (H, W, 3), row 0 at the top."""
        return self.display_target().read()[..., :3].copy()

    def save_png(self, path):
        """Tone-map the last frame and write it as PNG (written to a temporary name, then moved)."""
        save_png(path, self.tonemapped())

    # -- lifetime ------------------------------------------------------------------------

    def close(self):
        if self.ctx is None:
            return
        with self.ctx:
            for render_pass in reversed(self._passes):
                render_pass.release()
            self._passes = []
            self.geometry.release()
        if self._owns_context:
            self.ctx.release()
        self.ctx = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
