"""Shadow maps for every light in one depth atlas: six cube faces per point light, one
perspective view per spot light, one orthographic view per directional light. Also owns the
light and shadow-view storage buffers the lighting and voxel-injection shaders read."""
import math

import numpy as np

from .. import transforms
from ..constants import LIGHT_TYPE, MAX_LIGHTS, STORAGE_BINDING, TEXTURE_UNIT
from ..errors import VctError

CUBE_FACES = (  # (direction, up) in the order of cube_face() in glsl/lib/lights.glsl
    ((1, 0, 0), (0, -1, 0)), ((-1, 0, 0), (0, -1, 0)),
    ((0, 1, 0), (0, 0, 1)), ((0, -1, 0), (0, 0, -1)),
    ((0, 0, 1), (0, -1, 0)), ((0, 0, -1), (0, -1, 0)),
)
NEAR_PLANE = 0.01


class ShadowPass:
    def __init__(self, ctx, programs, geometry, tile_size=1024, normal_offset_texels=1.5):
        self.ctx = ctx
        self.geometry = geometry
        self.tile_size = tile_size
        self.normal_offset_texels = normal_offset_texels
        self.program = programs.program(vertex_shader="shadow.vert", fragment_shader="shadow.frag")
        self.atlas = None
        self.framebuffer = None
        self.light_buffer = ctx.buffer(reserve=64 * MAX_LIGHTS)
        self.view_buffer = ctx.buffer(reserve=96 * 6 * MAX_LIGHTS)
        self.light_count = 0

    def _ensure_atlas(self, tiles):
        columns = min(tiles, 6) or 1
        rows = max(1, math.ceil(tiles / columns))
        size = (columns * self.tile_size, rows * self.tile_size)
        if self.atlas is None or self.atlas.size != size:
            self._release_atlas()
            self.atlas = self.ctx.depth_texture(size)
            self.atlas.compare_func = "<="
            self.atlas.filter = (self.ctx.LINEAR, self.ctx.LINEAR)
            self.atlas.repeat_x = self.atlas.repeat_y = False
            self.framebuffer = self.ctx.framebuffer(depth_attachment=self.atlas)
        return columns

    def _views(self, light, bounds):
        """[(view_projection, texel_world_per_w)] of one light."""
        lo, hi = bounds
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        margin = 2.0 / self.tile_size  # a border of texels so 2x2 filtering never leaves its tile
        if light.type == "directional":
            center = (lo + hi) / 2.0
            radius = max(np.linalg.norm(hi - lo) / 2.0, 1e-3)
            up = (0, 1, 0) if abs(light.direction[1]) < 0.99 else (1, 0, 0)
            view = transforms.look_at(center - light.direction * 2.0 * radius, center, up)
            proj = transforms.orthographic(radius, radius, radius * 0.5, radius * 3.5)
            return [(proj @ view, 2.0 * radius / self.tile_size)]
        far = max(np.max(np.linalg.norm(corners - light.position, axis=1)) * 1.01, NEAR_PLANE * 4)
        if light.type == "spot":
            half = math.radians(min(light.outer_angle_deg, 89.0))
            tan_half = math.tan(half) * (1.0 + margin)
            up = (0, 1, 0) if abs(light.direction[1]) < 0.99 else (1, 0, 0)
            view = transforms.look_at(light.position, light.position + light.direction, up)
            proj = transforms.perspective(math.degrees(2 * math.atan(tan_half)), 1.0, NEAR_PLANE, far)
            return [(proj @ view, 2.0 * tan_half / self.tile_size)]
        tan_half = 1.0 + margin
        proj = transforms.perspective(math.degrees(2 * math.atan(tan_half)), 1.0, NEAR_PLANE, far)
        return [(proj @ transforms.look_at(light.position, light.position + np.array(d), up), 2.0 * tan_half / self.tile_size)
                for d, up in CUBE_FACES]

    def update(self, scene):
        """Pack the lights, build their views and render the atlas."""
        lights = [light for _, light in scene.lights()]
        if len(lights) > MAX_LIGHTS:
            raise VctError(f"{len(lights)} lights, at most {MAX_LIGHTS} are supported", source=scene.source, field="lights")
        bounds = scene.bounds()
        views, light_rows = [], []
        for light in lights:
            first = -1
            if light.cast_shadows:
                first = len(views)
                views += self._views(light, bounds)
            range_ = light.range if light.type != "directional" else 0.0
            light_rows.append(np.concatenate([
                light.position, [LIGHT_TYPE[light.type]],
                light.direction, [range_],
                light.intensity, [first],
                [math.cos(math.radians(light.inner_angle_deg)), math.cos(math.radians(light.outer_angle_deg)), 0.0, 0.0],
            ]))
        self.light_count = len(lights)
        if light_rows:
            self.light_buffer.write(np.array(light_rows, "f4").tobytes())
        columns = self._ensure_atlas(len(views))
        rows = []
        self.framebuffer.use()
        self.framebuffer.clear(depth=1.0)
        self.ctx.enable_only(self.ctx.DEPTH_TEST)
        atlas_w, atlas_h = self.atlas.size
        for index, (view_projection, texel_world) in enumerate(views):
            x, y = (index % columns) * self.tile_size, (index // columns) * self.tile_size
            self.ctx.viewport = (x, y, self.tile_size, self.tile_size)
            self.program.set(view_projection=transforms.gl_bytes(view_projection))
            self.geometry.draw(self.program, scene)
            rows.append(np.concatenate([
                np.asarray(view_projection, "f4").T.ravel(),
                [x / atlas_w, y / atlas_h, self.tile_size / atlas_w, self.tile_size / atlas_h],
                [texel_world, 1.0 / self.tile_size, 0.0, 0.0],
            ]))
        if rows:
            self.view_buffer.write(np.array(rows, "f4").tobytes())

    def bind(self, *handles):
        """Bind atlas and buffers, set light uniforms on the programs that read them."""
        self.atlas.use(TEXTURE_UNIT["SHADOW_ATLAS"])
        self.light_buffer.bind_to_storage_buffer(STORAGE_BINDING["LIGHTS"])
        self.view_buffer.bind_to_storage_buffer(STORAGE_BINDING["SHADOW_MATRICES"])
        for handle in handles:
            handle.set(light_count=self.light_count, shadow_normal_offset=self.normal_offset_texels)

    def _release_atlas(self):
        for resource in (self.framebuffer, self.atlas):
            if resource is not None:
                resource.release()
        self.atlas = self.framebuffer = None

    def release(self):
        self._release_atlas()
        self.light_buffer.release()
        self.view_buffer.release()
        self.program.release()
