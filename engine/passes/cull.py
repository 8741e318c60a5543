"""Culling pass: writes a draw list's indirect commands and instances on the GPU, for the views a
raster pass draws it into (the camera, the shadow views, the voxelization's jobs).

A DrawList is what one raster pass draws of the scene (engine/gpu/scene_buffers.py SceneBuffers): its
items, one per draw and cluster of the draw's mesh, and its commands, one per bucket (the
program variant and face culling the pass draws a draw with), mesh, material and cluster,
sorted by bucket. The pass culls each item against each view (glsl/cull/cull_clusters.comp:
frustum, world box): a command draws its cluster once per draw and view that kept it. A raster
pass then issues one multi-draw-indirect a bucket (`DrawList.draw`), whatever the scene holds;
every command draws one material, so a fragment's texture array is the same across its draw.

A list can also be written by the host (`DrawList.write`): the voxelizer's few moved draws."""
import math

import moderngl
import numpy as np

from ..core.constants import LIST_GROUP, MAX_DRAW_VIEWS, VERTEX_ATTRIBUTES, struct_dtype
from ..core.errors import VctError
from ..gpu.bindings import program_used
from ..gpu.functions import write_buffer

VIEW_DTYPE = struct_dtype("DrawView")
COMMAND_WORDS = 5  # count, instance count, first index, base vertex, base instance


class DrawList:
    """A raster pass's commands and instances over the scene's buffers. `bucket_of(flags)` maps
    arrays of DRAW_FLAGS to bucket numbers in range(bucket_count); `room` is how many instances a
    command has room for per view and item (the voxelizer's lists draw an item twice: as the
    voxels hold it and as it is)."""

    def __init__(self, ctx, bucket_of, bucket_count, room=1):
        self.ctx = ctx
        self.bucket_of, self.bucket_count, self.room = bucket_of, bucket_count, room
        self.items = self.table = self.commands = self.instances = self.views = None
        self.item_count = self.command_count = self.capacity = 0
        self.bucket_ranges = [(0, 0)] * bucket_count  # (first command, command count) per bucket
        self.built_for = None  # (buffers' layout, pool version) the items were built for
        self.view_count = 0
        self._vertex_arrays = {}  # handle -> (program, pool version, instance buffer, vao)

    # -- the items and commands, from the scene's buffers ------------------------------------

    def build(self, buffers):
        """Items and commands for the scene buffers' draws, where their layout or pool changed."""
        key = (id(buffers), buffers.layout, buffers.pool.version)
        if key == self.built_for:
            return
        self.built_for = key
        draws = np.arange(buffers.draw_count)
        first_cluster = np.array([entry.first_cluster for entry in buffers.draw_entries], np.int64)
        cluster_count = np.array([entry.cluster_count for entry in buffers.draw_entries], np.int64)
        buckets = self.bucket_of(buffers.draw_flags) if len(draws) else np.zeros(0, np.int64)
        item_draw = np.repeat(draws, cluster_count)
        item_cluster = np.repeat(first_cluster, cluster_count) + _ranks(cluster_count)
        # A command per bucket, material and cluster (a cluster belongs to one mesh); within a
        # bucket in the order of their first draws, so that surfaces meeting at one depth are
        # drawn in the scene's order.
        keys = np.stack([buckets[item_draw], buffers.draw_material[item_draw], item_cluster], axis=1)
        unique, item_command, per_command = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
        item_command = item_command.ravel()
        first_draw = np.full(len(unique), len(draws), np.int64)
        np.minimum.at(first_draw, item_command, item_draw)
        order = np.lexsort((unique[:, 2], first_draw, unique[:, 0]))
        unique, per_command = unique[order], per_command[order]
        item_command = np.argsort(order)[item_command]
        clusters = buffers.pool.clusters[unique[:, 2]]
        capacity = per_command * self.room
        table = np.zeros((len(unique), 4), np.uint32)
        table[:, 0] = clusters["indices"][:, 1]
        table[:, 1] = clusters["indices"][:, 0]
        table[:, 2] = clusters["indices"][:, 2]
        table[:, 3] = np.r_[0, np.cumsum(capacity)[:-1]] if len(capacity) else []
        items = np.zeros((len(item_draw), 4), np.uint32)
        items[:, 0], items[:, 1], items[:, 2] = item_draw, item_cluster, item_command
        self.item_count, self.command_count, self.capacity = len(items), len(unique), int(capacity.sum())
        self.bucket_ranges = [(int(np.searchsorted(unique[:, 0], b)), int(np.count_nonzero(unique[:, 0] == b)))
                              for b in range(self.bucket_count)]
        self.items = buffer_holding(self.ctx, self.items, items)
        self.table = buffer_holding(self.ctx, self.table, table)
        self._ensure_commands(self.command_count)

    def _ensure_commands(self, count):
        size = 4 * COMMAND_WORDS * max(count, 1)
        if self.commands is None or self.commands.size < size:
            if self.commands is not None:
                self.commands.release()
            self.commands = self.ctx.buffer(reserve=size)

    def ensure_instances(self, count):
        """Room for `count` instances (the vertex arrays follow a new buffer)."""
        size = 4 * max(count, 1)
        if self.instances is None or self.instances.size < size:
            held = 0
            if self.instances is not None:
                held = self.instances.size
                self.instances.release()
            self.instances = self.ctx.buffer(reserve=max(size, 2 * held))

    def write_views(self, views):
        """The views (VIEW_DTYPE records) the list is culled for and drawn into."""
        if len(views) > MAX_DRAW_VIEWS:
            raise VctError(f"{len(views)} views of one draw list, at most {MAX_DRAW_VIEWS}", field="views")
        self.view_count = len(views)
        self.views = buffer_holding(self.ctx, self.views, views, keep=True)

    def write(self, commands, instances, bucket_ranges):
        """Commands (uint32 (k, 5)) and instances written by the host, with their buckets'
        (first command, count)."""
        self._ensure_commands(len(commands))
        self.ensure_instances(len(instances))
        if len(commands):
            write_buffer(self.commands, np.ascontiguousarray(commands, np.uint32).tobytes())
        if len(instances):
            write_buffer(self.instances, np.ascontiguousarray(instances, np.uint32).tobytes())
        self.bucket_ranges = list(bucket_ranges)

    # -- drawing -------------------------------------------------------------------------------

    def vertex_array(self, handle, buffers):
        """`handle`'s vertex array over the pool's buffers and the list's instances."""
        pool = buffers.pool
        held = self._vertex_arrays.get(handle)
        if held is not None and held[0] is handle.program and held[1] == pool.version and held[2] is self.instances:
            return held[3]
        if held is not None:
            held[3].release()
        program = handle.program
        # The attributes the compiler kept, and padding for the others.
        layout = " ".join(f"{size}f" if name in program else f"{4 * size}x" for name, size in VERTEX_ATTRIBUTES)
        names = [name for name, _ in VERTEX_ATTRIBUTES if name in program]
        vao = self.ctx.vertex_array(program, [(pool.vertices, layout, *names), (self.instances, "1u4 /i", "in_instance")],
                                    index_buffer=pool.indices, index_element_size=4)
        self._vertex_arrays[handle] = (program, pool.version, self.instances, vao)
        return vao

    def draw(self, bucket, handle, buffers, resources):
        """Draw a bucket's commands with `handle` and its `resources` (ProgramHandle.bind; one
        multi-draw-indirect); nothing where it has none."""
        first, count = self.bucket_ranges[bucket]
        if count:
            handle.bind(resources)
            self.vertex_array(handle, buffers).render_indirect(self.commands, moderngl.TRIANGLES, count=count, first=first)
            program_used(handle.program)
            buffers.draw_calls += 1

    def release(self):
        for _, _, _, vao in self._vertex_arrays.values():
            vao.release()
        self._vertex_arrays.clear()
        for buffer in (self.items, self.table, self.commands, self.instances, self.views):
            if buffer is not None:
                buffer.release()


class CullPass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.reset = programs.compute("cull/reset_commands.comp", reads=("SSBO_COMMAND_TABLE",), writes=("SSBO_DRAW_COMMANDS",))
        self.cull = programs.compute("cull/cull_clusters.comp",
                                     reads=("SSBO_DRAWS", "SSBO_HELD_DRAWS", "SSBO_DRAW_VIEWS", "SSBO_DRAW_ITEMS", "SSBO_CLUSTERS"),
                                     writes=("SSBO_DRAW_COMMANDS", "SSBO_DRAW_INSTANCES"))

    def run(self, draw_list, buffers, views, held_draws=None):
        """Cull `draw_list`'s items (built from `buffers`) for `views` (VIEW_DTYPE records, each
        with its items and tests set): writes its commands and instances."""
        draw_list.build(buffers)
        draw_list.write_views(views)
        draw_list.ensure_instances(draw_list.capacity * len(views))
        self.reset.set(view_count=len(views))
        self.reset.run(max(1, math.ceil(draw_list.command_count / LIST_GROUP)), SSBO_COMMAND_TABLE=draw_list.table,
                       SSBO_DRAW_COMMANDS=draw_list.commands)
        self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)
        if draw_list.item_count and len(views):
            self.cull.run(math.ceil(max(int(v["items"][1]) for v in views) / LIST_GROUP), len(views),
                          SSBO_DRAWS=buffers.draws, SSBO_HELD_DRAWS=held_draws if held_draws is not None else buffers.draws,
                          SSBO_DRAW_VIEWS=draw_list.views, SSBO_DRAW_ITEMS=draw_list.items,
                          SSBO_CLUSTERS=buffers.pool.cluster_buffer, SSBO_DRAW_COMMANDS=draw_list.commands,
                          SSBO_DRAW_INSTANCES=draw_list.instances)
        self.ctx.memory_barrier(self.ctx.COMMAND_BARRIER_BIT | self.ctx.VERTEX_ATTRIB_ARRAY_BARRIER_BIT
                                | self.ctx.SHADER_STORAGE_BARRIER_BIT)

    def release(self):
        self.reset.release()
        self.cull.release()


def view_records(count):
    """`count` zeroed VIEW_DTYPE records."""
    return np.zeros(count, VIEW_DTYPE)


def _ranks(counts):
    """0..c-1 for each count c, concatenated."""
    total = int(np.sum(counts))
    return np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)


def buffer_holding(ctx, buffer, array, keep=False):
    """A buffer holding `array`: `buffer` where it has room (and `keep`), else a new one."""
    data = np.ascontiguousarray(array).tobytes() or bytes(16)
    if keep and buffer is not None and buffer.size >= len(data):
        write_buffer(buffer, data)
        return buffer
    if buffer is not None:
        buffer.release()
    return ctx.buffer(data)
