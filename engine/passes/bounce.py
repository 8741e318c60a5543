"""Multi-bounce pass: re-injects into the voxel radiance the diffuse light each voxel gathers
with the 6 diffuse cones, using its normal distribution and albedo:
    L_out = L_base + k_d sum_j w_j L_in(p, w_j)
Each run reads one set of face views and writes the other; repeating it adds one bounce each
time and converges to the infinite-bounce radiance since k_d < 1."""
import numpy as np

from ..constants import IMAGE_UNIT, TEXTURE_UNIT
from .voxelize import bind_faces, bind_output, use_faces

# Convergence: stop when the light the remaining bounces would add is below this fraction of
# the total, or close the series once successive increments shrink by a steady ratio.
CONVERGENCE_TOLERANCE = 2e-3
RATIO_SETTLED = 0.01
MAX_ITERATIONS = 64


class BouncePass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.program = programs.compute("voxel_bounce.comp")
        self.extrapolate = programs.compute("voxel_extrapolate.comp")

    def run(self, voxels, cone_uniforms, source_set, interleave=1, phase=0):
        """One bounce from face set `source_set` into the other; returns the set written (its
        level 0: mipmap it before cones read it). With interleave K > 1 only one voxel class
        in K gathers again (class `phase`), the others reuse their last gather."""
        target_set = 1 - source_set
        self.program.set(**voxels.uniforms(), **cone_uniforms, interleave=interleave, interleave_phase=phase % interleave)
        bind_output(voxels.gathered, IMAGE_UNIT["GATHERED"])
        voxels.radiance.use(TEXTURE_UNIT["VOXEL_RADIANCE"])
        voxels.normal.use(TEXTURE_UNIT["VOXEL_NORMAL"])
        voxels.albedo.use(TEXTURE_UNIT["VOXEL_ALBEDO"])
        use_faces(voxels.face_sets[source_set])
        bind_faces(voxels.face_sets[target_set])
        voxels.dispatch_per_voxel(self.program, voxels.occupied_count)
        return target_set

    def converge(self, voxels, cone_uniforms, source_set):
        """Bounce until converged: track the grid's total radiance T_k; once the increments
        D_k = T_k - T_(k-1) shrink by a settled ratio r, add the rest of the geometric series
        in one step. Returns (face set, bounce iterations run)."""
        totals = [voxels.face_total(source_set)]
        ratios = []
        for iteration in range(1, MAX_ITERATIONS + 1):
            source_set = self.run(voxels, cone_uniforms, source_set)
            voxels.mipmap_faces(source_set)
            totals.append(voxels.face_total(source_set))
            increment = totals[-1] - totals[-2]
            if np.all(increment <= CONVERGENCE_TOLERANCE * totals[-1]):
                return source_set, iteration
            if len(totals) >= 3:
                previous = totals[-2] - totals[-3]
                ratios.append(np.where(previous > 0, increment / np.maximum(previous, 1e-30), 0.0))
            if len(ratios) >= 2 and np.all(np.abs(ratios[-1] - ratios[-2]) <= RATIO_SETTLED) and np.all(ratios[-1] < 1):
                r = np.clip(ratios[-1], 0.0, 0.99)
                return self._close_series(voxels, source_set, r / (1.0 - r)), iteration
        return source_set, MAX_ITERATIONS

    def _close_series(self, voxels, latest_set, gain):
        older_set = 1 - latest_set
        use_faces(voxels.face_sets[latest_set])
        bind_faces(voxels.face_sets[older_set], read=True)
        self.extrapolate.set(gain=tuple(float(g) for g in gain))
        voxels.dispatch_per_voxel(self.extrapolate, voxels.occupied_count)
        voxels.mipmap_faces(older_set)
        return older_set

    def release(self):
        self.program.release()
        self.extrapolate.release()
