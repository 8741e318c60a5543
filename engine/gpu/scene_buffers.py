"""GPU copies of the scene (engine/scene/table.py's arrays), shared by every pass that
rasterizes it, and written where the table changed since the last sync:

- every mesh in one vertex buffer and one index buffer (`MeshPool`), each mesh once however
  many draws use it, its triangles sorted into spatial clusters (`MeshClusters`) with their
  bounds in a buffer of Cluster records, which the culling pass tests (engine/passes/cull.py);
- a DrawRecord per draw (world matrix, material) and a MaterialRecord per material in
  storage buffers;
- the materials' textures as layers of a few 2D texture arrays (`MaterialTextures`), bound once
  for every draw;
- per draw, the flags that choose the program variant and face culling it is drawn with
  (DRAW_FLAGS), from which each pass sorts its draws into buckets.

A frame draws the scene with a fixed number of indirect multi-draws a pass and bucket, its
commands written on the GPU: the host's work does not grow with the draws or the materials.
Also here: the environment map and the emitters' buffers."""
import ctypes
import math

import numpy as np

from ..core.constants import ALPHA_BLENDED, ALPHA_OPAQUE, MATERIAL_TEXTURE_ARRAYS, MAX_DRAWS, SHADER_ENUMS, VERTEX_FLOATS, struct_dtype
from ..core.errors import VctError
from ..scene.emitters import frame_emitters
from ..scene.model import IDENTITY_UV, TEXTURE_FIELDS
from .functions import (GL_LINEAR, GL_LINEAR_MIPMAP_LINEAR, GL_RGBA, GL_RGBA8, GL_SRGB8_ALPHA8, GL_TEXTURE_2D_ARRAY,
                        GL_TEXTURE_MAG_FILTER, GL_TEXTURE_MIN_FILTER, GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T,
                        GL_UNPACK_ALIGNMENT, GL_UNSIGNED_BYTE, WRAP_MODES, gl_functions, write_buffer)

# The vertex attributes are VERTEX_ATTRIBUTES (engine/core/constants.py). Meshes without
# texture coordinates or tangents get zeros there, without vertex colours white.
CLUSTER_TRIANGLES = 1024  # meshes are split into clusters of about this many triangles
CLUSTER_DTYPE = struct_dtype("Cluster")
DRAW_DTYPE = struct_dtype("DrawRecord")
MOTION_DTYPE = np.dtype([("matrix", "<f4", 16)])  # a mat4 per draw, column-major (SSBO_DRAW_MOTIONS)
MOTION_BYTES = MOTION_DTYPE.itemsize
MATERIAL_DTYPE = struct_dtype("MaterialRecord")
# What a draw is drawn with, as bits: its material has a normal map (NORMAL_MAP programs), it
# has vertex colours, a second texture coordinate set or texture transforms (VERTEX_EXTRAS
# programs), its material is double-sided (no face culling), alpha-tested (cut out, or
# dissolved) or blended (drawn over the opaque image, not into the G-buffer), its world matrix
# mirrors (its front faces turn clockwise).
DRAW_FLAGS = {"normal_mapped": 1, "extras": 2, "double_sided": 4, "alpha_tested": 8, "mirrored": 16, "blended": 32}
NO_TEXTURE = -1
# A pool's buffers start with room for this many floats of vertices and indices, and grow by
# doubling; they are packed anew where more than half of them and this many are left unused.
POOL_START = 1 << 16


class MeshClusters:
    """The clusters of a mesh: triangles binned by centroid into a grid of cells over the
    mesh's bounds, each cell's triangles a contiguous range of the sorted index buffer."""

    def __init__(self, positions, triangles):
        count = len(triangles)
        cells = max(1, min(16, round((count / CLUSTER_TRIANGLES) ** (1 / 3))))
        centroids = positions[triangles].mean(axis=1)
        lo, hi = positions.min(axis=0), positions.max(axis=0)
        cell = np.clip(((centroids - lo) / np.maximum(hi - lo, 1e-30) * cells).astype(np.int64), 0, cells - 1)
        keys = (cell[:, 0] * cells + cell[:, 1]) * cells + cell[:, 2]
        order = np.argsort(keys, kind="stable")
        self.triangles = triangles[order]
        starts = np.flatnonzero(np.r_[True, np.diff(keys[order]) != 0])
        self.first = starts * 3                                    # first index of each cluster
        self.count = np.diff(np.r_[starts, count]) * 3              # indices in each cluster
        corners = positions[self.triangles]
        self.lo = np.minimum.reduceat(corners.min(axis=1), starts)  # local bounds of each cluster
        self.hi = np.maximum.reduceat(corners.max(axis=1), starts)


class TextureArray:
    """A 2D texture array of RGBA8 layers (sRGB-decoded where `srgb`), mipmapped, sampled
    trilinearly with the given wrap modes: made through GL 4.5's own calls, as moderngl makes
    no sRGB arrays. Not anisotropically: on llvmpipe anisotropic filtering doubles the
    G-buffer's cost on Sponza, and it filters the voxelizer's stretched voxel footprints with
    so many samples that a voxelization of Sponza takes minutes instead of a second."""

    def __init__(self, ctx, images, srgb, wrap_s, wrap_t):
        self.ctx = ctx
        gl = self.gl = gl_functions(ctx)
        height, width = images[0].shape[:2]
        self.size, self.layers = (width, height), len(images)
        name = ctypes.c_uint(0)
        gl.glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, ctypes.byref(name))
        self.glo = name.value
        levels = max(width, height).bit_length()
        gl.glTextureStorage3D(self.glo, levels, GL_SRGB8_ALPHA8 if srgb else GL_RGBA8, width, height, len(images))
        gl.glPixelStorei(GL_UNPACK_ALIGNMENT, 4)  # rows of RGBA8 are whole words
        for layer, image in enumerate(images):
            data = np.ascontiguousarray(image)
            gl.glTextureSubImage3D(self.glo, 0, 0, 0, layer, width, height, 1, GL_RGBA, GL_UNSIGNED_BYTE, data.ctypes.data)
        gl.glGenerateTextureMipmap(self.glo)
        for parameter, value in ((GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR), (GL_TEXTURE_MAG_FILTER, GL_LINEAR),
                                 (GL_TEXTURE_WRAP_S, WRAP_MODES[wrap_s]), (GL_TEXTURE_WRAP_T, WRAP_MODES[wrap_t])):
            gl.glTextureParameteri(self.glo, parameter, value)

    def use(self, unit):
        self.gl.glBindTextureUnit(unit, self.glo)

    def memory_bytes(self):
        """RGBA8 layers with their mip chains (x 4/3)."""
        return int(self.size[0] * self.size[1] * 4 * self.layers * 4 / 3)

    def release(self):
        if self.glo:
            self.gl.glDeleteTextures(1, ctypes.byref(ctypes.c_uint(self.glo)))
            self.glo = 0


class MaterialTextures:
    """The materials' textures as layers of at most MATERIAL_TEXTURE_ARRAYS texture arrays, one
    array for each size, colour encoding and pair of wrap modes, so that every draw samples
    them without a texture bound for it. Where a scene's textures come in more kinds than there
    are arrays, the kinds with the fewest textures are resampled (Pillow, Lanczos) to the
    nearest size of the same encoding and wrapping; an array holds at most the driver's layer
    limit. A texture's place is `slot(texture)`: its array << 16 | its layer."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.arrays = []
        self.slots = {}      # id(Texture) -> (Texture, slot)

    def sync(self, textures):
        """Hold exactly `textures` (scene.Texture objects); True where the arrays were made anew
        (every slot may have moved)."""
        live = {id(t): t for t in textures}
        if live.keys() == self.slots.keys() and all(self.slots[key][0] is t for key, t in live.items()):
            return False
        limit = self.ctx.info["GL_MAX_TEXTURE_SIZE"]
        for texture in live.values():
            height, width = texture.image.shape[:2]
            if max(width, height) > limit:
                raise VctError(f"{width}x{height} exceeds the driver's texture limit of {limit}", source=texture.name)
        groups = texture_groups(list(live.values()), self.ctx.info.get("GL_MAX_ARRAY_TEXTURE_LAYERS", 256))
        self._release_arrays()
        for index, ((size, srgb, wrap_s, wrap_t), members) in enumerate(groups):
            images = [_rgba(fitted(texture.image, size)) for texture in members]
            self.arrays.append(TextureArray(self.ctx, images, srgb, wrap_s, wrap_t))
            for layer, texture in enumerate(members):
                self.slots[id(texture)] = (texture, index << 16 | layer)
        return True

    def slot(self, texture):
        return NO_TEXTURE if texture is None else self.slots[id(texture)][1]

    def resources(self):
        """Every array, at the units from TEXTURE_UNIT["MATERIAL_TEXTURES"] on (the units past
        them are never sampled: no material names them)."""
        return {"TEX_MATERIAL_TEXTURES": tuple(self.arrays)}

    def memory_bytes(self):
        return sum(array.memory_bytes() for array in self.arrays)

    def _release_arrays(self):
        for array in self.arrays:
            array.release()
        self.arrays, self.slots = [], {}

    def release(self):
        self._release_arrays()


def texture_groups(textures, max_layers):
    """[((width, height), srgb, wrap_s, wrap_t), [Texture]] for at most MATERIAL_TEXTURE_ARRAYS
    arrays: textures grouped by size, encoding and wrapping, a group split where it holds more
    than `max_layers`; while there are too many, the smallest group goes into the group of the
    nearest size with its encoding and wrapping (its images resampled to that size)."""
    groups = {}
    for texture in textures:
        height, width = texture.image.shape[:2]
        groups.setdefault(((width, height), texture.srgb, texture.wrap_s, texture.wrap_t), []).append(texture)
    while sum(-(-len(members) // max_layers) for members in groups.values()) > MATERIAL_TEXTURE_ARRAYS:
        key = min(groups, key=lambda k: (len(groups[k]), k[0]))
        (width, height), *kind = key
        others = [k for k in groups if k != key and list(k[1:]) == kind]
        if not others:
            raise VctError(f"the scene's {len(textures)} textures need more than {MATERIAL_TEXTURE_ARRAYS} texture arrays "
                           "(one per size, colour encoding and pair of wrap modes)", field="textures")
        target = min(others, key=lambda k: (abs(math.log(k[0][0] * k[0][1] / (width * height))), k[0]))
        groups[target] += groups.pop(key)
    return [(key, members[start:start + max_layers]) for key, members in groups.items()
            for start in range(0, len(members), max_layers)]


def fitted(image, size):
    """`image` (uint8 H, W, C) at `size` (width, height), resampled where it differs."""
    if image.shape[1::-1] == tuple(size):
        return image
    from PIL import Image
    return np.asarray(Image.fromarray(np.squeeze(image)).resize(size, Image.LANCZOS)).reshape(size[1], size[0], -1)


class MeshEntry:
    """Where a mesh lies in the pool: its arrays, base vertex, first index and index count, and
    its clusters' first record and count."""

    def __init__(self, arrays, base_vertex, first_index, index_count, first_cluster, cluster_count):
        self.arrays = arrays
        self.base_vertex, self.first_index, self.index_count = base_vertex, first_index, index_count
        self.first_cluster, self.cluster_count = first_cluster, cluster_count


class MeshPool:
    """Every mesh of the scene in one vertex buffer (VERTEX_ATTRIBUTES, interleaved float32)
    and one index buffer (uint32, a mesh's indices from its own first vertex), its clusters in
    one buffer of Cluster records. A mesh given new arrays is appended anew; the space of what
    no draw uses any more is reclaimed by packing the buffers anew, when it is most of them.
    `version` counts the buffers made (vertex arrays over them are made again); `epoch` the
    packings (a mesh's place from before is no longer valid)."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.entries = {}  # id(Mesh) -> MeshEntry
        self.posed = {}    # a posed draw's key -> (Mesh, the MeshEntry of its own copy)
        self.clusters = np.zeros(0, CLUSTER_DTYPE)
        self.version = self.epoch = 0
        self._allocate(POOL_START, POOL_START)

    def _allocate(self, vertex_room, index_room):
        self.vertices = self.ctx.buffer(reserve=4 * VERTEX_FLOATS * vertex_room)
        self.indices = self.ctx.buffer(reserve=4 * index_room)
        self.vertex_room, self.index_room = vertex_room, index_room
        self.vertex_count = self.index_count = 0
        self.cluster_buffer = self.ctx.buffer(reserve=CLUSTER_DTYPE.itemsize)
        self.clusters = np.zeros(0, CLUSTER_DTYPE)
        self.version += 1

    def entry(self, mesh):
        """The MeshEntry of `mesh`, uploaded where it is new or holds new arrays."""
        entry = self.entries.get(id(mesh))
        if entry is not None and all(a is b for a, b in zip(entry.arrays, mesh.arrays())):
            return entry
        entry = self._append(mesh)
        self.entries[id(mesh)] = entry
        return entry

    def posed_entry(self, key, mesh):
        """The MeshEntry of a copy of `mesh` of its own for the posed draw `key` (its vertices
        the pose pass's to write, its clusters' bounds set_cluster_bounds'), made anew where
        the mesh's arrays changed."""
        held = self.posed.get(key)
        if held is not None and held[0] is mesh and all(a is b for a, b in zip(held[1].arrays, mesh.arrays())):
            return held[1]
        entry = self._append(mesh)
        self.posed[key] = (mesh, entry)
        return entry

    def set_cluster_bounds(self, entry, lo, hi):
        """Bound every cluster of `entry` (a posed copy) by the box (lo, hi) in its draw's frame."""
        records = self.clusters[entry.first_cluster:entry.first_cluster + entry.cluster_count]
        records["lo"][:, :3], records["hi"][:, :3] = lo, hi
        self.cluster_buffer.write(records.tobytes(), offset=entry.first_cluster * CLUSTER_DTYPE.itemsize)

    def _append(self, mesh):
        count = len(mesh.positions)
        columns = [mesh.positions, mesh.normals,
                   mesh.texcoords if mesh.texcoords is not None else np.zeros((count, 2)),
                   mesh.tangents if mesh.tangents is not None else np.zeros((count, 4)),
                   mesh.colors if mesh.colors is not None else np.ones((count, 3)),
                   mesh.texcoords1 if mesh.texcoords1 is not None else np.zeros((count, 2))]
        vertices = np.hstack([np.asarray(c, dtype="f4") for c in columns])
        clusters = MeshClusters(np.asarray(mesh.positions, np.float64), np.asarray(mesh.indices, np.int64).reshape(-1, 3))
        indices = clusters.triangles.astype("u4").ravel()
        self._reserve(count, len(indices))
        entry = MeshEntry(mesh.arrays(), self.vertex_count, self.index_count, len(indices), len(self.clusters),
                          len(clusters.first))
        self.vertices.write(vertices.tobytes(), offset=4 * VERTEX_FLOATS * self.vertex_count)
        self.indices.write(indices.tobytes(), offset=4 * self.index_count)
        records = np.zeros(len(clusters.first), CLUSTER_DTYPE)
        records["lo"][:, :3], records["hi"][:, :3] = clusters.lo, clusters.hi
        records["indices"][:, 0] = self.index_count + clusters.first
        records["indices"][:, 1] = clusters.count
        records["indices"][:, 2] = self.vertex_count
        self.clusters = np.concatenate([self.clusters, records])
        if self.cluster_buffer.size < self.clusters.nbytes:  # a new buffer, twice the size, holding them all
            self.cluster_buffer.release()
            self.cluster_buffer = self.ctx.buffer(reserve=2 * self.clusters.nbytes)
            self.cluster_buffer.write(self.clusters.tobytes())
        else:
            self.cluster_buffer.write(records.tobytes(), offset=entry.first_cluster * CLUSTER_DTYPE.itemsize)
        self.vertex_count += count
        self.index_count += len(indices)
        return entry

    def _reserve(self, vertices, indices):
        """Room for `vertices` and `indices` more: the buffers made anew, twice as large, their
        contents copied over."""
        if self.vertex_count + vertices <= self.vertex_room and self.index_count + indices <= self.index_room:
            return
        old_vertices, old_indices, old_clusters = self.vertices, self.indices, self.cluster_buffer
        vertex_count, index_count, clusters = self.vertex_count, self.index_count, self.clusters
        self._allocate(max(2 * self.vertex_room, vertex_count + vertices), max(2 * self.index_room, index_count + indices))
        if vertex_count:
            self.ctx.copy_buffer(self.vertices, old_vertices, 4 * VERTEX_FLOATS * vertex_count)
        if index_count:
            self.ctx.copy_buffer(self.indices, old_indices, 4 * index_count)
        self.vertex_count, self.index_count, self.clusters = vertex_count, index_count, clusters
        self.cluster_buffer.release()
        self.cluster_buffer = self.ctx.buffer(reserve=max(CLUSTER_DTYPE.itemsize, 2 * clusters.nbytes))
        if len(clusters):
            self.cluster_buffer.write(clusters.tobytes())
        for buffer in (old_vertices, old_indices, old_clusters):
            buffer.release()

    def retain(self, meshes, posed_keys=()):
        """Keep the entries of `meshes` and the posed copies of `posed_keys` only; where what
        the others held is most of the buffers, pack them anew with the kept ones alone (a new
        epoch: the posed copies hold their meshes' rest pose until posed again). True when
        packed."""
        live = {id(mesh): mesh for mesh in meshes}
        for key in [key for key in self.entries if key not in live]:
            del self.entries[key]
        posed_keys = set(posed_keys)
        for key in [key for key in self.posed if key not in posed_keys]:
            del self.posed[key]
        used = sum(entry.index_count for entry in self.entries.values()) + sum(e.index_count for _, e in self.posed.values())
        if self.index_count - used <= max(used, POOL_START):
            return False
        self.vertices.release()
        self.indices.release()
        self.cluster_buffer.release()
        self._allocate(POOL_START, POOL_START)
        self.entries = {}
        for mesh in live.values():
            self.entries[id(mesh)] = self._append(mesh)
        self.posed = {key: (mesh, self._append(mesh)) for key, (mesh, _) in self.posed.items()}
        self.epoch += 1
        return True

    def memory_bytes(self):
        return self.vertices.size + self.indices.size + self.cluster_buffer.size

    def release(self):
        for buffer in (self.vertices, self.indices, self.cluster_buffer):
            buffer.release()
        self.entries, self.posed = {}, {}


class SceneBuffers:
    """The GPU side of a SceneTable: its meshes (MeshPool), a DrawRecord per draw and a
    MaterialRecord per material in storage buffers, the materials' textures, and each draw's
    DRAW_FLAGS and mesh entry. `sync(table)` writes what changed since the last sync; `layout`
    counts the changes of what the passes sort their draws by (a draw's mesh, material or
    flags), after which their draw lists are made anew."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.pool = MeshPool(ctx)
        self.textures = MaterialTextures(ctx)
        self.draws = ctx.buffer(reserve=DRAW_DTYPE.itemsize)
        # Per draw the matrix taking its points in the world to where they were at the last
        # sync, W_prev W^-1 (identity where it did not move): temporal anti-aliasing's motion.
        self.motions = ctx.buffer(reserve=MOTION_BYTES)
        self.synced_world = np.zeros((0, 4, 4))  # each draw's world matrix at the last sync
        self.moving = np.zeros(0, np.int64)      # the draws whose motion is not the identity
        self.materials = ctx.buffer(reserve=MATERIAL_DTYPE.itemsize)
        self.structure = self.stamp = None
        self.layout = 0
        self.draw_count = 0
        self.draw_flags = np.zeros(0, np.int64)
        self.blended_count = 0     # draws whose material blends (DRAW_FLAGS "blended")
        self.draw_entries = []     # per draw its mesh's MeshEntry
        self.draw_material = np.zeros(0, np.int64)
        self.draw_calls = 0        # multi-draws issued, counted by the draw lists

    def sync(self, table):
        """Write what changed in `table` since the last sync."""
        if table.draw_count > MAX_DRAWS:
            raise VctError(f"{table.draw_count} mesh instances, at most {MAX_DRAWS} are drawn", field="scene")
        anew = table.structure != self.structure
        draws = np.arange(table.draw_count) if anew else table.changed_draws(self.stamp)
        materials = np.arange(len(table.materials)) if anew else np.flatnonzero(table.material_stamp > self.stamp)
        if anew or len(draws) or len(materials):
            if self.textures.sync({id(t): t for m in table.materials for t in m.textures()}.values()):
                materials = np.arange(len(table.materials))
            self._write_materials(table, materials)
            meshes = {int(slot) for slot in table.draw_mesh[draws]}
            entries = {slot: self.pool.entry(table.meshes[slot]) for slot in meshes}
            if anew or any(self.pool.entries.get(id(table.meshes[slot])) is not entry for slot, entry in entries.items()):
                if self.pool.retain(table.meshes, [posed_key(table, draw) for draw in table.posed_draws]):
                    draws = np.arange(table.draw_count)
            self._write_draws(table, draws, anew)
        self._write_motions(table, draws, anew)
        self.structure, self.stamp = table.structure, table.stamp

    def _write_motions(self, table, draws, anew):
        """The motion of the draws that changed since the last sync (`draws`), and the identity
        again for those that moved at the last sync and not since: the rows written are
        those, whatever the scene's size."""
        count = table.draw_count
        if anew or len(self.synced_world) != count:
            if self.motions.size < MOTION_BYTES * count:
                self.motions.release()
                self.motions = self.ctx.buffer(reserve=MOTION_BYTES * max(count, 1))
            if count:
                write_buffer(self.motions, np.tile(np.eye(4, dtype="f4"), (count, 1, 1)).tobytes())
            self.synced_world = table.draw_world.copy()
            self.moving = np.zeros(0, np.int64)
            return
        rows = np.union1d(self.moving, draws).astype(np.int64)
        if not len(rows):
            return
        motion = np.tile(np.eye(4), (len(rows), 1, 1))
        changed = np.isin(rows, draws)
        world, before = table.draw_world[rows[changed]], self.synced_world[rows[changed]]
        invertible = np.abs(np.linalg.det(world)) > 1e-12  # a draw scaled to nothing has no motion
        moved = motion[changed]
        moved[invertible] = before[invertible] @ np.linalg.inv(world[invertible])
        motion[changed] = moved
        self.synced_world[rows[changed]] = world
        columns = np.ascontiguousarray(np.swapaxes(motion, 1, 2), "f4").reshape(len(rows), 16)
        _write_rows(self.motions, columns.view(MOTION_DTYPE).ravel(), rows)
        self.moving = rows[~np.all(np.isclose(motion, np.eye(4)), axis=(1, 2))]

    def _write_materials(self, table, slots):
        if not len(slots):
            return
        if self.materials.size < MATERIAL_DTYPE.itemsize * len(table.materials):
            self.materials.release()
            self.materials = self.ctx.buffer(reserve=2 * MATERIAL_DTYPE.itemsize * len(table.materials))
        records = np.zeros(len(slots), MATERIAL_DTYPE)
        for record, slot in zip(records, slots):
            material_record(table.materials[slot], self.textures, record)
        _write_rows(self.materials, records, slots)

    def _write_draws(self, table, draws, anew):
        count = table.draw_count
        if anew or self.draw_count != count:
            self.draw_flags = np.zeros(count, np.int64)
            self.draw_entries = [None] * count
            self.draw_material = np.zeros(count, np.int64)
            self.draw_count = count
            if self.draws.size < DRAW_DTYPE.itemsize * count:
                self.draws.release()
                self.draws = self.ctx.buffer(reserve=DRAW_DTYPE.itemsize * max(count, 1))
        if not len(draws):
            return
        _write_rows(self.draws, draw_records(table.draw_world[draws], table.draw_material[draws],
                                             np.isin(draws, table.posed_draws)), draws)
        flags = np.array([draw_flags(table.draw(draw)) for draw in draws], np.int64)
        posed = set(table.poses)
        entries = [self.pool.posed_entry(posed_key(table, draw), table.meshes[slot]) if int(draw) in posed
                   else self.pool.entry(table.meshes[slot]) for draw, slot in zip(draws, table.draw_mesh[draws])]
        changed = anew or np.any(flags != self.draw_flags[draws]) or np.any(table.draw_material[draws] != self.draw_material[draws]) \
            or any(self.draw_entries[draw] is not entry for draw, entry in zip(draws, entries))
        self.draw_flags[draws] = flags
        self.blended_count = int(np.count_nonzero(self.draw_flags & DRAW_FLAGS["blended"]))
        self.draw_material[draws] = table.draw_material[draws]
        for draw, entry in zip(draws, entries):
            self.draw_entries[draw] = entry
        if changed:
            self.layout += 1

    def records(self):
        """What a program drawing the scene reads of it besides the textures: the draws and the
        materials."""
        return {"SSBO_DRAWS": self.draws, "SSBO_MATERIALS": self.materials}

    def motion_records(self):
        """The draws' motions since the last frame, as the G-buffer's motion reads them."""
        return {"SSBO_DRAW_MOTIONS": self.motions}

    def memory_bytes(self):
        return self.pool.memory_bytes() + self.draws.size + self.motions.size + self.materials.size

    def release(self):
        self.pool.release()
        self.textures.release()
        self.draws.release()
        self.motions.release()
        self.materials.release()


def posed_key(table, draw):
    """The key of a posed draw's own copy of its mesh in the pool."""
    return (table.structure, int(draw))


def draw_records(world, materials, posed):
    """DRAW_DTYPE records of world matrices (k, 4, 4), material indices (k,) and whether each
    draw is posed (k,)."""
    records = np.zeros(len(world), DRAW_DTYPE)
    records["world"] = np.swapaxes(world, 1, 2).reshape(-1, 16)
    records["info"][:, 0] = materials
    records["info"][:, 1] = posed
    return records


def draw_flags(draw):
    """The DRAW_FLAGS of a table.DrawView."""
    material = draw.material
    flags = 0
    if material.normal_texture is not None:
        flags |= DRAW_FLAGS["normal_mapped"]
    if vertex_extras(draw):
        flags |= DRAW_FLAGS["extras"]
    if material.double_sided:
        flags |= DRAW_FLAGS["double_sided"]
    if material.alpha_tested:
        flags |= DRAW_FLAGS["alpha_tested"]
    if material.alpha_mode == "BLEND":
        flags |= DRAW_FLAGS["blended"]
    if np.linalg.det(draw.world[:3, :3]) < 0:
        flags |= DRAW_FLAGS["mirrored"]
    return flags


def material_record(material, textures, record):
    """Fill a MATERIAL_DTYPE record from a scene.Material (glsl/lib/material.glsl)."""
    record["albedo_alpha"] = (*material.albedo, material.alpha)
    cutoff = {"OPAQUE": ALPHA_OPAQUE, "MASK": material.alpha_cutoff, "BLEND": ALPHA_BLENDED}[material.alpha_mode]
    record["emission_cutoff"] = (*material.emission, cutoff)
    record["surface"] = (material.roughness, material.metalness, material.specular, material.normal_scale)
    record["sides"][0] = int(material.double_sided)
    for field in TEXTURE_FIELDS:
        map_index = SHADER_ENUMS["MAP"][field.removesuffix("_texture").replace("metallic_roughness", "metal_rough")]
        record["maps"][map_index] = textures.slot(getattr(material, field))
        record["uv_sets"][map_index] = int(material.uv_sets.get(field, 0))
        (a, b, c), (d, e, f) = material.uv_transform(field)
        record["uv_rows"][2 * map_index] = (a, b, c, 0.0)
        record["uv_rows"][2 * map_index + 1] = (d, e, f, 0.0)


def _write_rows(buffer, records, rows):
    """Write `records` at rows `rows` of a buffer of such records: runs of consecutive rows in
    one write each."""
    size = records.dtype.itemsize
    rows = np.asarray(rows)
    breaks = np.flatnonzero(np.diff(rows) != 1) + 1
    for start, end in zip(np.r_[0, breaks], np.r_[breaks, len(rows)]):
        write_buffer(buffer, records[start:end].tobytes(), int(rows[start]) * size)


class EnvironmentMap:
    """The scene's environment (engine.scene.model.Environment) as one RGBA32F texture with its mip
    chain, repeating in u and clamped in v (glsl/lib/environment.glsl): the map, or one texel
    of a uniform sky's radiance; uploaded when the environment changes."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.texture = None
        self.environment = None
        self.upload(None)

    def upload(self, environment):
        """Hold `environment` (None: none)."""
        if self.texture is not None:
            self.texture.release()
        self.environment = environment
        if environment is not None and environment.image is not None:
            height, width = environment.image.shape[:2]
            limit = self.ctx.info["GL_MAX_TEXTURE_SIZE"]
            if max(width, height) > limit:
                raise VctError(f"{width}x{height} exceeds the driver's texture limit of {limit}", source=environment.name)
            rgb = environment.image
        else:
            rgb = np.zeros((1, 1, 3)) if environment is None else np.asarray(environment.radiance).reshape(1, 1, 3)
        rgba = np.concatenate([rgb, np.ones(rgb.shape[:2] + (1,))], axis=2).astype("f4")
        self.texture = self.ctx.texture((rgba.shape[1], rgba.shape[0]), 4, np.ascontiguousarray(rgba).tobytes(), dtype="f4")
        self.texture.build_mipmaps()
        self.texture.filter = (self.ctx.LINEAR_MIPMAP_LINEAR, self.ctx.LINEAR)
        self.texture.repeat_x, self.texture.repeat_y = True, False

    def resources(self):
        """The map, as glsl/lib/environment.glsl reads it."""
        return {"TEX_ENVIRONMENT": self.texture}

    def uniforms(self):
        """The uniforms of glsl/lib/environment.glsl."""
        environment = self.environment
        rotation = environment.rotation() if environment is not None else np.eye(3)
        return dict(environment_present=environment is not None,
                    environment_scale=float(environment.scale) if environment is not None else 0.0,
                    environment_rotation=tuple(np.asarray(rotation, "f4").T.reshape(-1)),
                    environment_texel_angle=2.0 * math.pi / self.texture.width)

    def release(self):
        if self.texture is not None:
            self.texture.release()
            self.texture = None


class EmitterBuffers:
    """The frame's emitters (engine/scene/emitters.py) in storage buffers, for the passes that light
    surfaces with them."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.triangles = self.patches = None
        self.count = 0
        self.upload(frame_emitters([]))

    def upload(self, emitters):
        self.release()
        # An empty storage buffer cannot be made: hold one zero record.
        self.triangles = self.ctx.buffer(emitters.triangles.tobytes() or bytes(emitters.triangles.dtype.itemsize))
        self.patches = self.ctx.buffer(emitters.patches.tobytes() or bytes(emitters.patches.dtype.itemsize))
        self.count = emitters.count

    def resources(self):
        """The emissive triangles and their patches, as glsl/lib/emitters.glsl reads them."""
        return {"SSBO_EMITTER_TRIANGLES": self.triangles, "SSBO_EMITTER_PATCHES": self.patches}

    def uniforms(self):
        return dict(emitter_patch_count=self.count)

    def release(self):
        for buffer in (self.triangles, self.patches):
            if buffer is not None:
                buffer.release()
        self.triangles = self.patches = None


def vertex_extras(draw):
    """Whether a draw's mesh has vertex colours or a second texture coordinate set, or its
    material reads set 1 or transforms its texture coordinates: the programs that pass them on
    and transform them (VERTEX_EXTRAS) draw it."""
    mesh, material = draw.mesh, draw.material
    return (mesh.colors is not None or mesh.texcoords1 is not None or any(material.uv_sets.values())
            or any(transform != IDENTITY_UV for transform in material.uv_transforms.values()))


def _rgba(image):
    """uint8 (H, W, C) with C in 1..4 -> (H, W, 4): grey to RGB, opaque where it has no alpha."""
    if image.ndim == 2:
        image = image[..., None]
    channels = image.shape[2]
    rgb = np.repeat(image[..., :1], 3, axis=2) if channels <= 2 else image[..., :3]
    alpha = image[..., -1:] if channels in (2, 4) else np.full(image.shape[:2] + (1,), 255, np.uint8)
    return np.ascontiguousarray(np.concatenate([rgb, alpha], axis=2))
