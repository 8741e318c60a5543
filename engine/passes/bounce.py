"""Multi-bounce pass: re-injects into the voxel radiance the diffuse light each voxel gathers
with the 6 diffuse cones, using its normal distribution and albedo:
    L_out = L_base + k_d sum_j w_j L_in(p, w_j)
Each run reads one set of face views and writes the other; repeating it adds one bounce each
time and converges to the infinite-bounce radiance since k_d < 1."""
import math

from ..constants import TEXTURE_UNIT
from .voxelize import RESOLVE_GROUP, bind_faces, use_faces

# Headless convergence: bounce until the light still missing is below this fraction of the total.
CONVERGENCE_TOLERANCE = 5e-3
MAX_ITERATIONS = 64


def iterations_to_converge(max_albedo, tolerance=CONVERGENCE_TOLERANCE):
    """Bounces k after which the missing light sum_{j>k} a^j <= tolerance * (1 - a) * sum_j a^j
    with a the largest diffuse albedo: a^(k+1) <= tolerance (1 - a)."""
    if max_albedo <= 0.0:
        return 0
    if max_albedo >= 1.0:
        return MAX_ITERATIONS
    return min(MAX_ITERATIONS, max(0, math.ceil(math.log(tolerance * (1.0 - max_albedo)) / math.log(max_albedo)) - 1))


class BouncePass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.program = programs.compute("voxel_bounce.comp")

    def run(self, voxels, cone_uniforms, source_set):
        """One bounce from face set `source_set` into the other; returns the set written."""
        target_set = 1 - source_set
        self.program.set(**voxels.uniforms(), **cone_uniforms)
        voxels.radiance.use(TEXTURE_UNIT["VOXEL_RADIANCE"])
        voxels.normal.use(TEXTURE_UNIT["VOXEL_NORMAL"])
        voxels.albedo.use(TEXTURE_UNIT["VOXEL_ALBEDO"])
        use_faces(voxels.face_sets[source_set])
        bind_faces(voxels.face_sets[target_set])
        groups = voxels.grid // RESOLVE_GROUP
        self.program.program.run(groups, groups, groups)
        self.ctx.memory_barrier(self.ctx.SHADER_IMAGE_ACCESS_BARRIER_BIT | self.ctx.TEXTURE_FETCH_BARRIER_BIT
                                | self.ctx.TEXTURE_UPDATE_BARRIER_BIT)
        voxels.mipmap_faces(target_set)
        return target_set

    def release(self):
        self.program.release()
