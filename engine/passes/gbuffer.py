"""G-buffer pass: rasterizes the scene from the camera into position, shading normal +
roughness, albedo + metalness and emission + dielectric F0 targets (material factors times
textures), with a depth buffer; back faces of single-sided materials are culled. Returns the
GBuffer the screen passes read."""
from contextlib import contextmanager

import numpy as np

from ..core.constants import DRAW_TEST_FRUSTUM, HDR_FORMAT
from ..gpu.scene_buffers import DRAW_FLAGS
from .cull import DrawList, view_records


class GBuffer:
    """The G-buffer targets, which the screen passes read (glsl/lib/gbuffer.glsl), and where
    each pixel's point was at the frame before (GBUF_PREVIOUS, drawn with motion alone: temporal
    anti-aliasing reads it)."""

    UNITS = ("GBUF_POSITION", "GBUF_NORMAL", "GBUF_ALBEDO", "GBUF_EMISSION")
    READS = tuple(f"TEX_{unit}" for unit in UNITS)  # what a program reading all of them declares
    TARGETS = (*UNITS, "GBUF_PREVIOUS")

    def __init__(self, ctx, size):
        self.size = size
        self.textures = [ctx.texture(size, 4, dtype=HDR_FORMAT if name in ("GBUF_POSITION", "GBUF_PREVIOUS") else "f2")
                         for name in self.TARGETS]
        for texture in self.textures:
            texture.filter = (ctx.NEAREST, ctx.NEAREST)
        self.depth = ctx.depth_texture(size)
        self.framebuffer = ctx.framebuffer(color_attachments=self.textures, depth_attachment=self.depth)

    def resources(self, *units):
        """The targets of `units` (default: all of them) by binding name, as a program reading
        them binds them."""
        return {f"TEX_{name}": texture for name, texture in zip(self.TARGETS, self.textures) if name in (units or self.UNITS)}

    def release(self):
        for resource in [self.framebuffer, self.depth, *self.textures]:
            resource.release()


@contextmanager
def culling_faces(ctx, culling):
    """Draws inside cull faces as `culling` (one of GBufferPass.CULLING) says: none, or the
    back faces with "ccw" or "cw" in front; the default state (no culling, ccw) after."""
    if culling != "none":
        ctx.front_face = culling
        ctx.enable(ctx.CULL_FACE)
    try:
        yield
    finally:
        if culling != "none":
            ctx.disable(ctx.CULL_FACE)
            ctx.front_face = "ccw"


def face_culling(flags):
    """Per draw's DRAW_FLAGS the index of its face culling in GBufferPass.CULLING: none for a
    double-sided material, else the back faces (clockwise in front under a mirroring matrix)."""
    return np.where(flags & DRAW_FLAGS["double_sided"], 0, np.where(flags & DRAW_FLAGS["mirrored"], 2, 1))


class GBufferPass:
    """Draws the scene's draw list (engine/passes/cull.py) into the G-buffer: a multi-draw a
    bucket, the buckets being the program variants (normal map or not, vertex extras or not)
    and the face culling (none for double-sided materials; back faces, counter-clockwise or,
    under a mirroring world matrix, clockwise in front)."""

    CULLING = ("none", "ccw", "cw")

    def __init__(self, ctx, programs, cull, size):
        self.ctx = ctx
        self.cull = cull
        # Per whether the material has a normal map (else no tangent is interpolated) and the draw
        # vertex colours, a second texture coordinate set or texture transforms (else none), and
        # whether the frame wants the motion (temporal anti-aliasing).
        self.programs = {(mapped, extras, motion): programs.program(
            {name: 1 for name, wanted in (("NORMAL_MAP", mapped), ("VERTEX_EXTRAS", extras), ("MOTION", motion)) if wanted},
            vertex_shader="gbuffer/draw_surfaces.vert", fragment_shader="gbuffer/draw_surfaces.frag",
            reads=("UBO_CAMERA", "SSBO_DRAWS", "SSBO_MATERIALS", "TEX_MATERIAL_TEXTURES",
                   *(("SSBO_DRAW_MOTIONS", "SSBO_POSE_PREVIOUS") if motion else ())))
            for mapped in (False, True) for extras in (False, True) for motion in (False, True)}
        self.buckets = [(mapped, extras, culling) for mapped in (False, True) for extras in (False, True)
                        for culling in self.CULLING]
        # A last bucket, never drawn, takes the blended draws (engine/passes/transparent.py).
        self.draw_list = DrawList(ctx, self.bucket_of, len(self.buckets) + 1)
        self.target = GBuffer(ctx, size)

    def bucket_of(self, flags):
        """The bucket of each draw's DRAW_FLAGS (an index of self.buckets; past them, blended)."""
        mapped = (flags & DRAW_FLAGS["normal_mapped"]) != 0
        extras = (flags & DRAW_FLAGS["extras"]) != 0
        bucket = (mapped * 2 + extras) * len(self.CULLING) + face_culling(flags)
        return np.where(flags & DRAW_FLAGS["blended"], len(self.buckets), bucket)

    def resize(self, size):
        self.target.release()
        self.target = GBuffer(self.ctx, size)

    def render(self, buffers, camera, motion=None):
        """Cull the scene's draws (SceneBuffers) against the frustum of `camera` (a
        frame.camera.FrameCamera) and draw them; with `motion` (the draws' motions and the posed
        vertices' previous positions, by binding name) where each point was at the frame before
        too."""
        views = view_records(1)
        views["view_projection"][0] = np.asarray(camera.view_projection, "f4").T.ravel()
        views["items"][0] = (0, 0, DRAW_TEST_FRUSTUM, 0)
        self.draw_list.build(buffers)
        views["items"][0, 1] = self.draw_list.item_count
        self.cull.run(self.draw_list, buffers, views)
        gbuffer = self.target
        gbuffer.framebuffer.use()
        self.ctx.viewport = (0, 0, *gbuffer.size)
        gbuffer.framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable_only(self.ctx.DEPTH_TEST)
        resources = {**buffers.records(), **buffers.textures.resources(), **camera.resources(), **(motion or {})}
        for bucket, (mapped, extras, culling) in enumerate(self.buckets):
            if not self.draw_list.bucket_ranges[bucket][1]:
                continue
            with culling_faces(self.ctx, culling):
                self.draw_list.draw(bucket, self.programs[mapped, extras, motion is not None], buffers, resources)
        return gbuffer

    def release(self):
        self.target.release()
        self.draw_list.release()
        for program in self.programs.values():
            program.release()
