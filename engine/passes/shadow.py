"""Shadow maps for every light in one depth atlas: six cube faces per point light, one
perspective view per spot light, one orthographic view per directional light. Returns the
ShadowMaps that the lighting and light-injection passes read. Only the tiles of the lights
whose inputs changed are redrawn, and of the views that see a caster that changed."""
import math

import numpy as np

from .. import transforms
from ..constants import LIGHT_TYPE, MAX_LIGHTS, MAX_SHADOW_VIEWS, struct_dtype
from ..errors import VctError
from ..gl_bindings import bind_texture, bind_uniform_block

CUBE_FACES = (  # (direction, up) in the order of cube_face() in glsl/lib/lights.glsl
    ((1, 0, 0), (0, -1, 0)), ((-1, 0, 0), (0, -1, 0)),
    ((0, 1, 0), (0, 0, 1)), ((0, -1, 0), (0, 0, -1)),
    ((0, 0, 1), (0, -1, 0)), ((0, 0, -1), (0, -1, 0)),
)
NEAR_PLANE = 0.01
NORMAL_OFFSET_TEXELS = 1.5  # shadow lookups move off the surface by this many texels


class ShadowMaps:
    """The depth atlas, the packed lights and their shadow views: what every pass that
    evaluates lights (glsl/lib/lights.glsl) reads."""

    def __init__(self, ctx, tile_size):
        self.ctx = ctx
        self.tile_size = tile_size
        self.atlas = self.framebuffer = None
        self.columns = 1
        self.light_buffer = ctx.buffer(reserve=struct_dtype("Light").itemsize * MAX_LIGHTS)
        self.view_buffer = ctx.buffer(reserve=struct_dtype("ShadowView").itemsize * MAX_SHADOW_VIEWS)
        self.light_count = 0

    def ensure_atlas(self, tiles):
        """An atlas with room for `tiles` views; True when it was (re)made (all tiles empty)."""
        columns = min(tiles, 6) or 1
        rows = max(1, math.ceil(tiles / columns))
        size = (columns * self.tile_size, rows * self.tile_size)
        if self.atlas is not None and self.atlas.size == size:
            return False
        self._release_atlas()
        self.columns = columns
        self.atlas = self.ctx.depth_texture(size)
        self.atlas.compare_func = "<="
        self.atlas.filter = (self.ctx.LINEAR, self.ctx.LINEAR)
        self.atlas.repeat_x = self.atlas.repeat_y = False
        self.framebuffer = self.ctx.framebuffer(depth_attachment=self.atlas)
        self.framebuffer.clear(depth=1.0)
        return True

    def tile_origin(self, index):
        return (index % self.columns) * self.tile_size, (index // self.columns) * self.tile_size

    def bind(self, handle):
        """Bind the atlas and buffers, and set the light uniforms of a program that reads them."""
        bind_texture(self.atlas, "SHADOW_ATLAS")
        bind_uniform_block(self.light_buffer, "LIGHTS")
        bind_uniform_block(self.view_buffer, "SHADOW_VIEWS")
        handle.set(light_count=self.light_count, shadow_normal_offset=NORMAL_OFFSET_TEXELS)

    def _release_atlas(self):
        for resource in (self.framebuffer, self.atlas):
            if resource is not None:
                resource.release()
        self.atlas = self.framebuffer = None

    def release(self):
        self._release_atlas()
        self.light_buffer.release()
        self.view_buffer.release()


class ShadowPass:
    def __init__(self, ctx, programs, geometry, tile_size):
        self.ctx = ctx
        self.geometry = geometry
        # Opaque materials are drawn depth only (no fragment shader: llvmpipe tests depth
        # before shading); alpha-tested ones through shadow/cut_out.frag, which cuts them out.
        self.depth_program = programs.program(vertex_shader="shadow/draw_depth.vert")
        # Cut-outs read their texture through its transform and set (VERTEX_EXTRAS): shadow/draw_depth.vert
        # passes both sets on for every draw.
        self.cut_out_program = programs.program({"VERTEX_EXTRAS": 1}, vertex_shader="shadow/draw_depth.vert", fragment_shader="shadow/cut_out.frag",
                                                reads=("TEX_BASE_COLOR_MAP",))
        self.maps = ShadowMaps(ctx, tile_size)
        self.drawn_tiles = []  # the tiles (views) the last render drew, in atlas order

    def _views(self, light, bounds):
        """[(view_projection, texel_world_per_w)] of one light."""
        lo, hi = bounds
        corners = transforms.box_corners(lo, hi)
        margin = 2.0 / self.maps.tile_size  # a border of texels so 2x2 filtering never leaves its tile
        if light.type == "directional":
            center = (lo + hi) / 2.0
            radius = max(np.linalg.norm(hi - lo) / 2.0, 1e-3)
            up = (0, 1, 0) if abs(light.direction[1]) < 0.99 else (1, 0, 0)
            view = transforms.look_at(center - light.direction * 2.0 * radius, center, up)
            proj = transforms.orthographic(radius, radius, radius * 0.5, radius * 3.5)
            return [(proj @ view, 2.0 * radius / self.maps.tile_size)]
        far = max(np.max(np.linalg.norm(corners - light.position, axis=1)) * 1.01, NEAR_PLANE * 4)
        if light.type == "spot":
            half = math.radians(min(light.outer_angle_deg, 89.0))
            tan_half = math.tan(half) * (1.0 + margin)
            up = (0, 1, 0) if abs(light.direction[1]) < 0.99 else (1, 0, 0)
            view = transforms.look_at(light.position, light.position + light.direction, up)
            proj = transforms.perspective(math.degrees(2 * math.atan(tan_half)), 1.0, NEAR_PLANE, far)
            return [(proj @ view, 2.0 * tan_half / self.maps.tile_size)]
        tan_half = 1.0 + margin
        proj = transforms.perspective(math.degrees(2 * math.atan(tan_half)), 1.0, NEAR_PLANE, far)
        return [(proj @ transforms.look_at(light.position, light.position + np.array(d), up), 2.0 * tan_half / self.maps.tile_size)
                for d, up in CUBE_FACES]

    def render(self, lights, draws, bounds, redraw=None, source=None, changed_casters=None):
        """Pack the lights and their views; draw the tiles of the lights whose indices are in
        `redraw` and of the views that see one of the world boxes `changed_casters` (every tile
        when both are None, or when the atlas had to be remade). Returns the maps."""
        if len(lights) > MAX_LIGHTS:
            raise VctError(f"{len(lights)} lights, at most {MAX_LIGHTS} are supported", source=source, field="lights")
        maps = self.maps
        views, light_rows, owners = [], [], []
        for index, light in enumerate(lights):
            first = -1
            if light.cast_shadows:
                first = len(views)
                light_views = self._views(light, bounds)
                views += light_views
                owners += [index] * len(light_views)
            range_ = light.range if light.type != "directional" else 0.0
            light_rows.append(([*light.position, LIGHT_TYPE[light.type]], [*light.direction, range_],
                               [*light.intensity, first],
                               [math.cos(math.radians(light.inner_angle_deg)), math.cos(math.radians(light.outer_angle_deg)), 0.0, 0.0]))
        maps.light_count = len(lights)
        if light_rows:
            maps.light_buffer.write(np.array(light_rows, struct_dtype("Light")).tobytes())
        if maps.ensure_atlas(len(views)):
            redraw = changed_casters = None
        everything = redraw is None and changed_casters is None
        changed_corners = transforms.box_corners(*np.array(changed_casters).transpose(1, 0, 2)) if changed_casters else None
        cut_out = [draw for draw in draws if draw.material.alpha_tested]
        opaque = [draw for draw in draws if not draw.material.alpha_tested]
        rows = []
        maps.framebuffer.use()
        self.ctx.enable_only(self.ctx.DEPTH_TEST)
        atlas_w, atlas_h = maps.atlas.size
        tile = maps.tile_size
        self.drawn_tiles = []
        for index, ((view_projection, texel_world), owner) in enumerate(zip(views, owners)):
            x, y = maps.tile_origin(index)
            sees_change = changed_corners is not None and not np.all(transforms.outside_frustum(changed_corners, view_projection))
            if everything or owner in (redraw or ()) or sees_change:
                self.drawn_tiles.append(index)
                self.ctx.viewport = (x, y, tile, tile)
                maps.framebuffer.clear(depth=1.0, viewport=(x, y, tile, tile))
                for program, subset in ((self.depth_program, opaque), (self.cut_out_program, cut_out)):
                    program.set(view_projection=transforms.gl_bytes(view_projection))
                    self.geometry.draw(program, subset, materials=program is self.cut_out_program,
                                       view_projection=view_projection)
            rows.append((np.asarray(view_projection).T.ravel(), [x / atlas_w, y / atlas_h, tile / atlas_w, tile / atlas_h],
                         [texel_world, 1.0 / tile, 0.0, 0.0]))
        if rows:
            maps.view_buffer.write(np.array(rows, struct_dtype("ShadowView")).tobytes())
        return maps

    def release(self):
        self.maps.release()
        self.depth_program.release()
        self.cut_out_program.release()
