"""Voxelization pass: the scene -> an N^3 grid every frame (geometry-shader dominant-axis
projection, conservative dilation, image-atomic fixed-point averaging), resolved into RGBA16F
3D textures of radiance (emission + injected direct light, premultiplied by opacity), normal
distribution and diffuse albedo, plus the six one-sided face views of the radiance that cones
read, all with hardware mipmaps."""
import math

import numpy as np

from ..constants import (GL_IMAGE_FORMAT, GRID_SIZES, IMAGE_UNIT, LIST_GROUP, STORAGE_BINDING, TEXTURE_UNIT,
                         VOLUME_GROUP, VOXEL_FACES, VOXEL_FORMAT, VOXEL_MEMORY_BUDGET)
from ..errors import VctError

SUMS = (  # accumulator image, GL format
    ("SUM_RADIANCE_R", "r32ui"), ("SUM_RADIANCE_G", "r32ui"), ("SUM_RADIANCE_B", "r32ui"),
    ("SUM_ALBEDO_R", "r32ui"), ("SUM_ALBEDO_G", "r32ui"), ("SUM_ALBEDO_B", "r32ui"),
    ("SUM_NORMAL_X", "r32i"), ("SUM_NORMAL_Y", "r32i"), ("SUM_NORMAL_Z", "r32i"),
    ("SUM_COUNT", "r32ui"),
)
# Mipmapped RGBA16F volumes held per grid: base radiance, normal, albedo, and two sets of six
# one-sided face views of the radiance (the set cones read and the set a bounce writes).
MIPMAPPED_VOLUMES = 4 + 2 * VOXEL_FACES  # + the bounce pass's gather cache


def voxel_memory_bytes(n):
    """GPU memory a grid of n^3 needs: 32-bit sums, mipmapped RGBA16F volumes (x 8/7) and the
    two lists of covered voxels (32 bits per voxel each, at most)."""
    return n ** 3 * (4 * len(SUMS) + MIPMAPPED_VOLUMES * 8 * 8 / 7 + 2 * 4)


def check_grid(ctx, n, source=None):
    """Refuse a grid size before anything is allocated."""
    if n not in GRID_SIZES:
        raise VctError(f"grid must be a power of two from {GRID_SIZES[0]} to {GRID_SIZES[-1]}, got {n}", source=source, field="grid")
    max_size = ctx.info.get("GL_MAX_3D_TEXTURE_SIZE", 2048)
    if n > max_size:
        raise VctError(f"grid {n} exceeds GL_MAX_3D_TEXTURE_SIZE {max_size}", source=source, field="grid")
    need = voxel_memory_bytes(n)
    if need > VOXEL_MEMORY_BUDGET:
        raise VctError(f"grid {n} needs {need / 2**30:.1f} GiB of voxel memory, over the budget of "
                       f"{VOXEL_MEMORY_BUDGET / 2**30:.1f} GiB", source=source, field="grid")


def bind_output(volume, unit, read=False):
    volume.bind_to_image(unit, read=read, write=True, format=GL_IMAGE_FORMAT["rgba16f"])


def bind_faces(volumes, first_unit=IMAGE_UNIT["OUT_DIRECTIONAL"], read=False):
    """Bind six face views to six consecutive image units (out_directional[0..5])."""
    for face, volume in enumerate(volumes):
        bind_output(volume, first_unit + face, read)


def use_faces(volumes):
    """Bind six face views to the sampler units voxel_directional[0..5]."""
    for face, volume in enumerate(volumes):
        volume.use(TEXTURE_UNIT["VOXEL_DIRECTIONAL"] + face)


class VoxelizePass:
    def __init__(self, ctx, programs, geometry):
        self.ctx = ctx
        self.geometry = geometry
        self.program = programs.program(vertex_shader="voxelize.vert", geometry_shader="voxelize.geom",
                                        fragment_shader="voxelize.frag")
        self.clear = programs.compute("voxel_clear.comp")
        self.resolve = programs.compute("voxel_resolve.comp")
        self.readback = programs.compute("voxel_readback.comp")
        self.grid = 0
        self.sums = []
        self.radiance = self.normal = self.albedo = None
        self.gathered = None  # last diffuse gather per voxel, for amortized bounces
        self.face_sets = []  # two lists of 6 face views; the bounce pass writes one from the other
        # Lists of covered voxels (count, then packed coordinates): this frame's and last frame's.
        self.occupied = self.previous_occupied = None
        self.occupied_count = self.previous_count = 0
        self.framebuffer = None
        self.region = None

    def _allocate(self, n):
        self._release_grid()
        self.grid = n
        for _, fmt in SUMS:
            dtype = "u4" if fmt == "r32ui" else "i4"
            self.sums.append(self.ctx.texture3d((n, n, n), 1, data=bytes(4 * n ** 3), dtype=dtype))
        self.radiance, self.normal, self.albedo, self.gathered = (self.new_volume() for _ in range(4))
        self.face_sets = [[self.new_volume() for _ in range(VOXEL_FACES)] for _ in range(2)]
        self.occupied, self.previous_occupied = (self.ctx.buffer(data=bytes(4 + 4 * n ** 3)) for _ in range(2))
        self.occupied_count = self.previous_count = 0
        self.framebuffer = self.ctx.empty_framebuffer((n, n))

    def new_volume(self):
        """An N^3 RGBA16F volume of zeros with a full mip chain, trilinear between levels."""
        n = self.grid
        volume = self.ctx.texture3d((n, n, n), 4, data=bytes(8 * n ** 3), dtype=VOXEL_FORMAT)
        volume.build_mipmaps()
        volume.filter = (self.ctx.LINEAR_MIPMAP_LINEAR, self.ctx.LINEAR)
        volume.repeat_x = volume.repeat_y = volume.repeat_z = False
        return volume

    @property
    def mip_count(self):
        return self.grid.bit_length()  # N = 2^k has levels 0..k

    def uniforms(self):
        center, size = self.region.center, self.region.size
        return dict(voxel_region_min=tuple(np.asarray(center) - size / 2.0), voxel_region_size=float(size),
                    voxel_grid=self.grid, voxel_size=float(size) / self.grid)

    def run(self, scene, grid, face_set=0):
        """Voxelize the scene (with direct light from the bound shadow maps) and resolve into the
        base volumes and face view set `face_set`."""
        if grid != self.grid:
            check_grid(self.ctx, grid, scene.source)
            self._allocate(grid)
        self.region = scene.region()
        self.previous_occupied, self.occupied = self.occupied, self.previous_occupied
        self.previous_count = self.occupied_count
        self.occupied.write(bytes(4))
        self.occupied.bind_to_storage_buffer(STORAGE_BINDING["OCCUPIED"])
        self.previous_occupied.bind_to_storage_buffer(STORAGE_BINDING["PREVIOUS_OCCUPIED"])
        self.program.set(**self.uniforms())
        for (name, fmt), texture in zip(SUMS, self.sums):
            texture.bind_to_image(IMAGE_UNIT[name], read=True, write=True, format=GL_IMAGE_FORMAT[fmt])
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, grid, grid)
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.CULL_FACE | self.ctx.BLEND)

        def material(node, world):
            m = node.material
            self.program.set(albedo=tuple(m.albedo), metalness=m.metalness, emission=tuple(m.emission))

        self.geometry.draw(self.program, scene, material)
        self.ctx.memory_barrier(self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.SHADER_STORAGE_BARRIER_BIT)
        self.occupied_count = int(np.frombuffer(self.occupied.read(4), dtype="u4")[0])
        for unit, volume in (("OUT_RADIANCE", self.radiance), ("OUT_NORMAL", self.normal), ("OUT_ALBEDO", self.albedo),
                             ("GATHERED", self.gathered)):
            bind_output(volume, IMAGE_UNIT[unit])
        bind_faces(self.face_sets[face_set])
        bind_faces(self.face_sets[1 - face_set], IMAGE_UNIT["OTHER_DIRECTIONAL"])
        self.dispatch_per_voxel(self.clear, self.previous_count)
        self.dispatch_per_voxel(self.resolve, self.occupied_count)

    def dispatch_per_voxel(self, handle, count):
        """Run a compute program once per entry of a voxel list (`count` entries), then make its
        image writes visible to the texture fetches, mipmaps and passes that follow."""
        if count:
            handle.program.run(math.ceil(count / LIST_GROUP))
        self.ctx.memory_barrier(self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.TEXTURE_FETCH_BARRIER_BIT
                                | self.ctx.TEXTURE_UPDATE_BARRIER_BIT)

    def read_volume(self, volume, level=0):
        """One mip level of a volume as float32 (n, n, n, 4), indexed [z, y, x]."""
        n = max(1, self.grid >> level)
        buffer = self.ctx.buffer(reserve=n ** 3 * 16)
        try:
            volume.use(TEXTURE_UNIT["VOXEL_INSPECT"])
            self.readback.set(level=level)
            buffer.bind_to_storage_buffer(STORAGE_BINDING["READBACK"])
            groups = math.ceil(n / VOLUME_GROUP)
            self.readback.program.run(groups, groups, groups)
            self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)
            return np.frombuffer(buffer.read(), dtype="f4").reshape(n, n, n, 4).copy()
        finally:
            buffer.release()

    def face_total(self, face_set):
        """Mean premultiplied radiance (rgb) of a face set over the grid, from the 1^3 levels."""
        top = self.mip_count - 1
        return sum(self.read_volume(volume, top)[0, 0, 0, :3].astype(np.float64) for volume in self.face_sets[face_set])

    def mipmap_faces(self, face_set):
        for volume in self.face_sets[face_set]:
            volume.build_mipmaps()

    def _release_grid(self):
        for resource in [*self.sums, *sum(self.face_sets, []), self.radiance, self.normal, self.albedo, self.gathered,
                         self.occupied, self.previous_occupied, self.framebuffer]:
            if resource is not None:
                resource.release()
        self.sums, self.face_sets = [], []
        self.radiance = self.normal = self.albedo = self.gathered = None
        self.occupied = self.previous_occupied = self.framebuffer = None
        self.grid = 0

    def release(self):
        self._release_grid()
        self.program.release()
        self.clear.release()
        self.resolve.release()
        self.readback.release()
