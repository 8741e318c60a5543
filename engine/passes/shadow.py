"""Shadow maps for every light in one depth atlas: six cube faces per point light, one
perspective view per spot light, and per directional light one orthographic view of the whole
scene followed by cascade_count views fitted to slices of the camera's frustum, finest first
(the pixels' light looks up the finest that holds them; the voxels', which must not change with
the camera, the whole-scene view). Returns the ShadowMaps that the lighting and
light-injection passes read. A tile is drawn again when its view moved (a light that moved or
turned, a cascade the camera left) or its view sees a caster that changed."""
import ctypes
import math
from typing import NamedTuple

import numpy as np

from ..core import transforms
from ..core.constants import DRAW_TEST_FRUSTUM, LIGHT_TYPE, MAX_LIGHTS, MAX_SHADOW_CASCADES, MAX_SHADOW_VIEWS, struct_dtype
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
CASCADE_REACH = 3.0   # each cascade's slice of the view reaches this many times as deep as the one before it
CASCADE_NEAREST_REACH = 5.0  # metres: the finest cascade reaches at least this deep (the camera's near field)
CASCADE_SLACK = 1.15  # a cascade holds its slice's box this much wider, and is kept while it still holds it
NORMAL_OFFSET_TEXELS = 1.5  # shadow lookups move off the surface by this many texels times sin(angle to the light)
GL_CLIP_DISTANCES = [0x3000 + plane for plane in range(4)]  # GL_CLIP_DISTANCE0..3: a view's frustum sides (draw_depth.vert)
GL_SCISSOR_TEST = 0x0C11


def view_up(direction):
    """An up vector for a view looking along `direction`: +y, or +x where it looks nearly along y."""
    return (0, 1, 0) if abs(direction[1]) < 0.99 else (1, 0, 0)


class View(NamedTuple):
    """A shadow view: its view-projection and the world size of a texel per unit of clip w;
    for a cascade, what it was fitted to (`fitted`: the light's direction and the scene's
    bounds, as bytes) and its box in the light's frame ((lo_x, lo_y), (hi_x, hi_y))."""

    view_projection: np.ndarray
    texel_world: float
    fitted: bytes = None
    box: tuple = None


def cascade_count(bounds):
    """How many camera cascades a directional light has in a scene of `bounds`: as many as it
    takes, each reaching 1/CASCADE_REACH as deep as the next, from as deep as the bounds are
    across to CASCADE_NEAREST_REACH or less; at least 1, at most MAX_SHADOW_CASCADES."""
    lo, hi = bounds
    ratio = max(float(np.linalg.norm(hi - lo)), 1e-3) / CASCADE_NEAREST_REACH
    return int(np.clip(1 + math.ceil(math.log(max(ratio, 1.0), CASCADE_REACH)), 1, MAX_SHADOW_CASCADES))


def cascade_views(direction, bounds, camera, tile_size, held=()):
    """cascade_count(bounds) orthographic Views along `direction`, each holding a slice of the
    frustum of `camera` (a FrameCamera; through the pixels' centres), finest first. The slices
    start where the scene's bounds do in depth; the last reaches as deep as the bounds are
    across, each before it 1/CASCADE_REACH as deep. A view holds its slice's box in the light's
    frame, cut to the scene's and CASCADE_SLACK wider, its half sizes rounded up to steps of
    2^(1/4) and its centre snapped to whole texels of a light frame fixed in the world, so a
    camera that moves or turns does not drag the texels over the scene (no crawling shadow
    edges). A view of `held` (the cascades as the tiles hold them, in order) is kept while it
    holds its slice's box and is at most twice as wide: a camera that turns a little or walks a
    step redraws none. A view's depth range spans the scene's bounds, which hold every
    caster."""
    lo, hi = bounds
    fitted = np.concatenate([direction, lo, hi]).astype("f8").tobytes()
    diameter = max(float(np.linalg.norm(hi - lo)), 1e-3)
    light_frame = transforms.look_at(np.zeros(3), direction, view_up(direction))  # looks along the light: depth -z
    scene_corners = transforms.box_corners(lo, hi)
    scene_light = transforms.transform_points(light_frame, scene_corners)
    scene_lo, scene_hi = scene_light[:, :2].min(axis=0), scene_light[:, :2].max(axis=0)
    top, depth_span = scene_light[:, 2].max(), np.ptp(scene_light[:, 2])
    margin = 0.01 * diameter
    ndc = np.array([(x, y, z, 1.0) for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)])
    corners = ndc @ np.linalg.inv(camera.centred_view_projection).T
    corners = corners[:, :3] / corners[:, 3:]
    near_corners, far_corners = corners[:4], corners[4:]
    near_depth, far_depth = ((c[0] - camera.position) @ camera.forward for c in (near_corners, far_corners))
    start = float(np.clip(((scene_corners - camera.position) @ camera.forward).min(), near_depth, far_depth))

    def at_depth(depth):  # the frustum's four edges where they reach `depth`
        f = (np.clip(depth, near_depth, far_depth) - near_depth) / (far_depth - near_depth)
        return near_corners + (far_corners - near_corners) * f

    views = []
    count = cascade_count(bounds)
    for k in range(count):
        depths = [start + diameter / CASCADE_REACH ** (count - k) if k else start,
                  start + diameter / CASCADE_REACH ** (count - 1 - k)]
        slice_xy = transforms.transform_points(light_frame, np.concatenate([at_depth(d) for d in depths]))[:, :2]
        lo_xy = np.maximum(slice_xy.min(axis=0), scene_lo)
        hi_xy = np.maximum(np.minimum(slice_xy.max(axis=0), scene_hi), lo_xy)
        kept = held[k] if k < len(held) else None
        if (kept is not None and kept.fitted == fitted and np.all(kept.box[0] <= lo_xy) and np.all(hi_xy <= kept.box[1])
                and np.all(np.subtract(kept.box[1], kept.box[0]) <= 2.0 * np.maximum(hi_xy - lo_xy, 1e-4))):
            views.append(kept)
            continue
        half = 2.0 ** (np.ceil(np.log2(np.maximum(CASCADE_SLACK * (hi_xy - lo_xy) / 2.0, 1e-4)) * 4.0) / 4.0)
        texel = 2.0 * half / tile_size
        centre = np.round((lo_xy + hi_xy) / 2.0 / texel) * texel
        shift = np.eye(4)
        shift[:3, 3] = (-centre[0], -centre[1], -top)
        projection = transforms.orthographic(half[0], half[1], -margin, depth_span + margin)
        views.append(View(projection @ shift @ light_frame, float(texel.max()), fitted, (centre - half, centre + half)))
    return views


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
        self.held = []         # the Views the tiles hold, in atlas order
        self.cascaded = []     # (first cascade's view index, direction, cascade count) of each directional light with shadows
        self.bounds = None     # the scene's bounds the views were fitted to

    def _views(self, light, bounds, camera, held):
        """The Views of one light; a directional light's cascades fitted to `camera`, keeping
        those of `held` (its cascades as the tiles hold them) that still fit (cascade_views)."""
        lo, hi = bounds
        corners = transforms.box_corners(lo, hi)
        margin = 2.0 / self.maps.tile_size  # a border of texels so 2x2 filtering never leaves its tile
        if light.type == "directional":
            center = (lo + hi) / 2.0
            radius = max(np.linalg.norm(hi - lo) / 2.0, 1e-3)
            view = transforms.look_at(center - light.direction * 2.0 * radius, center, view_up(light.direction))
            proj = transforms.orthographic(radius, radius, radius * 0.5, radius * 3.5)
            return [View(proj @ view, 2.0 * radius / self.maps.tile_size),
                    *cascade_views(light.direction, bounds, camera, self.maps.tile_size, held)]
        far = max(np.max(np.linalg.norm(corners - light.position, axis=1)) * 1.01, NEAR_PLANE * 4)
        if light.type == "spot":
            half = math.radians(min(light.outer_angle_deg, 89.0))
            tan_half = math.tan(half) * (1.0 + margin)
            view = transforms.look_at(light.position, light.position + light.direction, view_up(light.direction))
            proj = transforms.perspective(math.degrees(2 * math.atan(tan_half)), 1.0, NEAR_PLANE, far)
            return [View(proj @ view, 2.0 * tan_half / self.maps.tile_size)]
        tan_half = 1.0 + margin
        proj = transforms.perspective(math.degrees(2 * math.atan(tan_half)), 1.0, NEAR_PLANE, far)
        return [View(proj @ transforms.look_at(light.position, light.position + np.array(d), up),
                     2.0 * tan_half / self.maps.tile_size) for d, up in CUBE_FACES]

    def render(self, lights, buffers, bounds, camera, changed_casters=None, source=None):
        """Pack the lights and their views (the directional lights' cascades fitted to `camera`,
        a FrameCamera); draw the scene's draws (SceneBuffers) into the tiles whose view moved
        and those whose view sees one of the world boxes `changed_casters` (None: every tile;
        every tile too when the atlas had to be remade). Returns the maps."""
        if len(lights) > MAX_LIGHTS:
            raise VctError(f"{len(lights)} lights, at most {MAX_LIGHTS} are supported", source=source, field="lights")
        maps = self.maps
        views, light_rows, cascaded = [], [], []
        for light in lights:
            first, cascades = -1, 0
            if light.cast_shadows:
                first = len(views)
                light_views = self._views(light, bounds, camera, self.held[first + 1:first + 1 + MAX_SHADOW_CASCADES])
                views += light_views
                if light.type == "directional":
                    cascades = len(light_views) - 1  # after its whole-scene view
                    cascaded.append((first + 1, light.direction, cascades))
            range_ = light.range if light.type != "directional" else 0.0
            light_rows.append(([*light.position, LIGHT_TYPE[light.type]], [*light.direction, range_],
                               [*light.intensity, first],
                               [math.cos(math.radians(light.inner_angle_deg)), math.cos(math.radians(light.outer_angle_deg)),
                                cascades, 0.0]))
        self.cascaded, self.bounds = cascaded, bounds
        maps.light_count = len(lights)
        if light_rows:
            write_buffer(maps.light_buffer, np.array(light_rows, struct_dtype("Light")).tobytes())
        if maps.ensure_atlas(len(views)):
            self.held, changed_casters = [], None
        everything = changed_casters is None
        changed_corners = transforms.box_corners(*np.array(changed_casters).transpose(1, 0, 2)) if changed_casters else None
        drawn, regions = [], {}
        for index, view in enumerate(views):
            if everything or self._moved(index, view):
                drawn.append(index)
            elif changed_corners is not None:
                seen = ~transforms.outside_frustum(changed_corners, view.view_projection)
                if seen.any():
                    drawn.append(index)
                    regions[index] = self._region(view.view_projection, changed_corners[seen])
        self._place(views, drawn, buffers, everything, regions)
        return maps

    def _region(self, view_projection, corners):
        """The texels of a tile (x, y, width, height, from its corner) that boxes given by
        their corners (..., 8, 3) may cover as its view sees them, a texel wider each way: where
        only they changed, only these are drawn again. The whole tile where a box reaches
        behind the view's eye, or where the driver cannot give each tile of a batch its own
        scissor box (no viewport indices)."""
        tile = self.maps.tile_size
        clip = transforms.clip_points(view_projection, corners.reshape(-1, 3))
        if not self.viewport_index or np.any(clip[:, 3] <= 1e-9):
            return 0, 0, tile, tile
        texels = (np.clip(clip[:, :2] / clip[:, 3:], -1.0, 1.0) * 0.5 + 0.5) * tile
        lo = np.maximum(np.floor(texels.min(axis=0)).astype(int) - 1, 0)
        hi = np.minimum(np.ceil(texels.max(axis=0)).astype(int) + 1, tile)
        return int(lo[0]), int(lo[1]), int(hi[0] - lo[0]), int(hi[1] - lo[1])

    def follow_camera(self, buffers, camera):
        """Fit the directional lights' cascades to `camera` (a FrameCamera), keeping those that
        still hold their slices, and draw those that moved. Returns whether any did."""
        views = list(self.held)
        for first, direction, count in self.cascaded:
            views[first:first + count] = cascade_views(direction, self.bounds, camera, self.maps.tile_size,
                                                       views[first:first + count])
        drawn = [index for index, view in enumerate(views) if self._moved(index, view)]
        self.drawn_tiles = drawn
        if drawn:
            self._place(views, drawn, buffers, False)
        return bool(drawn)

    def _moved(self, index, view):
        return index >= len(self.held) or not np.array_equal(self.held[index].view_projection, view.view_projection)

    def _place(self, views, drawn, buffers, whole_atlas, regions=None):
        """Write the Views' records and draw the tiles of the views whose indices are in `drawn`
        (of those in `regions`, {index: (x, y, width, height) in the tile}, that part alone)."""
        maps, tile = self.maps, self.maps.tile_size
        atlas_w, atlas_h = maps.atlas.size
        rows = []
        for index, view in enumerate(views):
            x, y = maps.tile_origin(index)
            rows.append((np.asarray(view.view_projection).T.ravel(), [x / atlas_w, y / atlas_h, tile / atlas_w, tile / atlas_h],
                         [view.texel_world, 1.0 / tile, 0.0, 0.0]))
        if rows:
            write_buffer(maps.view_buffer, np.array(rows, struct_dtype("ShadowView")).tobytes())
        self.held = views
        self.drawn_tiles = drawn
        if drawn:
            whole = (0, 0, tile, tile)
            self._draw_tiles(buffers, [(views[index].view_projection, maps.tile_origin(index), (regions or {}).get(index, whole))
                                       for index in drawn], whole_atlas)

    def _draw_tiles(self, buffers, tiles, whole_atlas):
        """Clear the tiles ((view_projection, origin, region) each: the region of the tile to
        draw, x, y, width, height from its origin), then cull the scene's draws for them and draw
        them in: a batch of up to `batch` tiles at a time, each tile a viewport of the batch
        scissored to its region (one batch, the whole atlas, without viewport indices, each
        region its whole tile)."""
        maps, tile = self.maps, self.maps.tile_size
        atlas_w, atlas_h = maps.atlas.size
        boxes = [(x + rx, y + ry, width, height) for _, (x, y), (rx, ry, width, height) in tiles]
        if whole_atlas:
            maps.framebuffer.use()
            maps.framebuffer.clear(depth=1.0)
        else:
            for box in boxes:
                clear_depth(maps.atlas, box)
        self.draw_list.build(buffers)
        for start in range(0, len(tiles), self.batch):
            batch = tiles[start:start + self.batch]
            views = view_records(len(batch))
            for view, (view_projection, (x, y), _) in zip(views, batch):
                view["view_projection"] = np.asarray(view_projection, "f4").T.ravel()
                # NDC in the tile -> NDC in the atlas: x' = x scale + offset.
                view["tile"] = ((2 * x + tile) / atlas_w - 1.0, (2 * y + tile) / atlas_h - 1.0, tile / atlas_w, tile / atlas_h)
                view["items"] = (0, self.draw_list.item_count, DRAW_TEST_FRUSTUM, 0)
            self.cull.run(self.draw_list, buffers, views)
            maps.framebuffer.use()
            self.ctx.enable_only(self.ctx.DEPTH_TEST)
            if self.viewport_index:
                functions = gl_functions(self.ctx)
                rects = np.array([(x, y, tile, tile) for _, (x, y), _ in batch], np.float32)
                functions.glViewportArrayv(0, len(batch), rects.ctypes.data_as(ctypes.POINTER(ctypes.c_float)))
                scissors = np.array(boxes[start:start + self.batch], np.int32)
                functions.glScissorArrayv(0, len(batch), scissors.ctypes.data_as(ctypes.POINTER(ctypes.c_int)))
                self.ctx.enable_direct(GL_SCISSOR_TEST)
            else:
                self.ctx.viewport = (0, 0, atlas_w, atlas_h)
                for plane in GL_CLIP_DISTANCES:
                    self.ctx.enable_direct(plane)
            depth_reads = {**buffers.records(), "SSBO_DRAW_VIEWS": self.draw_list.views}
            self.draw_list.draw(0, self.depth_program, buffers, depth_reads)
            self.draw_list.draw(1, self.cut_out_program, buffers, {**depth_reads, **buffers.textures.resources()})
            if self.viewport_index:
                self.ctx.disable_direct(GL_SCISSOR_TEST)
            else:
                for plane in GL_CLIP_DISTANCES:
                    self.ctx.disable_direct(plane)
        self.ctx.viewport = (0, 0, atlas_w, atlas_h)  # every viewport of the array

    def release(self):
        self.maps.release()
        self.draw_list.release()
        self.depth_program.release()
        self.cut_out_program.release()
