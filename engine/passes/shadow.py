"""Shadow maps for every light in one depth atlas: six cube faces per point light, one
perspective view per spot light, one orthographic view per directional light. Returns the
ShadowMaps that the lighting and light-injection passes read. Only the tiles of the lights
whose inputs changed are redrawn, and of the views that see a caster that changed."""
import ctypes
import math

import numpy as np

from ..core import transforms
from ..core.constants import DRAW_TEST_FRUSTUM, LIGHT_TYPE, MAX_LIGHTS, MAX_SHADOW_VIEWS, struct_dtype
from ..core.errors import VctError
from ..gpu.functions import clear_depth, gl_functions, write_buffer
from ..gpu.scene_buffers import DRAW_FLAGS
from .cull import DrawList, view_records

CUBE_FACES = (  # (direction, up) in the order of cube_face() in glsl/lib/lights.glsl
    ((1, 0, 0), (0, -1, 0)), ((-1, 0, 0), (0, -1, 0)),
    ((0, 1, 0), (0, 0, 1)), ((0, -1, 0), (0, 0, -1)),
    ((0, 0, 1), (0, -1, 0)), ((0, 0, -1), (0, -1, 0)),
)
NEAR_PLANE = 0.01
NORMAL_OFFSET_TEXELS = 1.5  # shadow lookups move off the surface by this many texels times sin(angle to the light)
GL_CLIP_DISTANCES = [0x3000 + plane for plane in range(4)]  # GL_CLIP_DISTANCE0..3: a view's frustum sides (draw_depth.vert)


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

    def resources(self):
        """The atlas and the lights' buffers, as a program evaluating lights binds them."""
        return {"TEX_SHADOW_ATLAS": self.atlas, "UBO_LIGHTS": self.light_buffer, "UBO_SHADOW_VIEWS": self.view_buffer}

    def uniforms(self):
        """The light uniforms of glsl/lib/lights.glsl."""
        return dict(light_count=self.light_count, shadow_normal_offset=NORMAL_OFFSET_TEXELS)

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
    """Draws the scene's draw list (engine/passes/cull.py) into the atlas's tiles that need it,
    every tile in one multi-draw a bucket: opaque materials depth only (no fragment shader:
    llvmpipe tests depth before shading), alpha-tested ones through shadow/cut_out.frag, which
    cuts them out. Each instance lands in its view's tile (shadow/draw_depth.vert)."""

    def __init__(self, ctx, programs, cull, tile_size):
        self.ctx = ctx
        self.cull = cull
        # Where a vertex shader may choose the viewport, a batch of tiles is a viewport array.
        self.viewport_index = "GL_ARB_shader_viewport_layer_array" in ctx.extensions
        self.batch = ctx.info["GL_MAX_VIEWPORTS"] if self.viewport_index else MAX_SHADOW_VIEWS
        defines = {"VIEWPORT_INDEX": 1} if self.viewport_index else {}
        self.depth_program = programs.program(defines or None, vertex_shader="shadow/draw_depth.vert",
                                              reads=("SSBO_DRAWS", "SSBO_DRAW_VIEWS", "SSBO_MATERIALS"))
        # Cut-outs read their texture through its transform and set (VERTEX_EXTRAS): shadow/draw_depth.vert
        # passes both sets on for every draw.
        self.cut_out_program = programs.program({"VERTEX_EXTRAS": 1, **defines}, vertex_shader="shadow/draw_depth.vert",
                                                fragment_shader="shadow/cut_out.frag",
                                                reads=("SSBO_DRAWS", "SSBO_DRAW_VIEWS", "SSBO_MATERIALS", "TEX_MATERIAL_TEXTURES"))
        self.draw_list = DrawList(ctx, lambda flags: ((flags & DRAW_FLAGS["alpha_tested"]) != 0).astype(np.int64), 2)
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

    def render(self, lights, buffers, bounds, redraw=None, source=None, changed_casters=None):
        """Pack the lights and their views; draw the scene's draws (SceneBuffers) into the tiles
        of the lights whose indices are in `redraw` and of the views that see one of the world
        boxes `changed_casters` (every tile when both are None, or when the atlas had to be
        remade). Returns the maps."""
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
            write_buffer(maps.light_buffer, np.array(light_rows, struct_dtype("Light")).tobytes())
        if maps.ensure_atlas(len(views)):
            redraw = changed_casters = None
        everything = redraw is None and changed_casters is None
        changed_corners = transforms.box_corners(*np.array(changed_casters).transpose(1, 0, 2)) if changed_casters else None
        rows = []
        atlas_w, atlas_h = maps.atlas.size
        tile = maps.tile_size
        self.drawn_tiles = []
        for index, ((view_projection, texel_world), owner) in enumerate(zip(views, owners)):
            x, y = maps.tile_origin(index)
            sees_change = changed_corners is not None and not np.all(transforms.outside_frustum(changed_corners, view_projection))
            if everything or owner in (redraw or ()) or sees_change:
                self.drawn_tiles.append(index)
            rows.append((np.asarray(view_projection).T.ravel(), [x / atlas_w, y / atlas_h, tile / atlas_w, tile / atlas_h],
                         [texel_world, 1.0 / tile, 0.0, 0.0]))
        if rows:
            write_buffer(maps.view_buffer, np.array(rows, struct_dtype("ShadowView")).tobytes())
        if self.drawn_tiles:
            self._draw_tiles(buffers, [(views[index][0], maps.tile_origin(index)) for index in self.drawn_tiles],
                             everything)
        return maps

    def _draw_tiles(self, buffers, tiles, whole_atlas):
        """Clear the tiles ((view_projection, origin) each), then cull the scene's draws for
        them and draw them in: a batch of up to `batch` tiles at a time, each tile a viewport of
        the batch (one batch, the whole atlas, without viewport indices)."""
        maps, tile = self.maps, self.maps.tile_size
        atlas_w, atlas_h = maps.atlas.size
        if whole_atlas:
            maps.framebuffer.use()
            maps.framebuffer.clear(depth=1.0)
        else:
            for _, (x, y) in tiles:
                clear_depth(maps.atlas, (x, y, tile, tile))
        self.draw_list.build(buffers)
        for start in range(0, len(tiles), self.batch):
            batch = tiles[start:start + self.batch]
            views = view_records(len(batch))
            for view, (view_projection, (x, y)) in zip(views, batch):
                view["view_projection"] = np.asarray(view_projection, "f4").T.ravel()
                # NDC in the tile -> NDC in the atlas: x' = x scale + offset.
                view["tile"] = ((2 * x + tile) / atlas_w - 1.0, (2 * y + tile) / atlas_h - 1.0, tile / atlas_w, tile / atlas_h)
                view["items"] = (0, self.draw_list.item_count, DRAW_TEST_FRUSTUM, 0)
            self.cull.run(self.draw_list, buffers, views)
            maps.framebuffer.use()
            self.ctx.enable_only(self.ctx.DEPTH_TEST)
            if self.viewport_index:
                rects = np.array([(x, y, tile, tile) for _, (x, y) in batch], np.float32)
                gl_functions(self.ctx).glViewportArrayv(0, len(batch), rects.ctypes.data_as(ctypes.POINTER(ctypes.c_float)))
            else:
                self.ctx.viewport = (0, 0, atlas_w, atlas_h)
                for plane in GL_CLIP_DISTANCES:
                    self.ctx.enable_direct(plane)
            depth_reads = {**buffers.records(), "SSBO_DRAW_VIEWS": self.draw_list.views}
            self.draw_list.draw(0, self.depth_program, buffers, depth_reads)
            self.draw_list.draw(1, self.cut_out_program, buffers, {**depth_reads, **buffers.textures.resources()})
            if not self.viewport_index:
                for plane in GL_CLIP_DISTANCES:
                    self.ctx.disable_direct(plane)
        self.ctx.viewport = (0, 0, atlas_w, atlas_h)  # every viewport of the array

    def release(self):
        self.maps.release()
        self.draw_list.release()
        self.depth_program.release()
        self.cut_out_program.release()
