"""The diffuse gather of the voxels: each voxel of a list traces the lecture's 6 cones from its
surface point through the face views, G = sum_j w_j L(p, w_j). A bounce is a gather followed
by composing the face views again (passes/faces.py); the image interpolates the gathers per
pixel (passes/cone_trace.py). Also sorts the covered voxels into interleave classes for the
progressive bounce, and closes the bounce series by extrapolation."""
import numpy as np

from ..constants import CLASS_BLOCK, CLASS_FACINGS, IMAGE_UNIT, STORAGE_BINDING, TEXTURE_UNIT
from ..voxel_grid import bind_image


class GatherPass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.program = programs.compute("voxel_gather.comp")
        self.classes = programs.compute("voxel_classes.comp")
        self.extrapolate_program = programs.compute("voxel_extrapolate.comp")

    def sort_classes(self, grid, interleave):
        """Sort the covered voxels into `interleave` classes (unless already sorted so), each
        grouped by block and facing: class c of the list is grid.class_segments[c] = (first, count)."""
        if grid.classes_for == (grid.version, interleave):
            return
        buckets = max(grid.n // CLASS_BLOCK, 1) ** 3 * CLASS_FACINGS  # per class: (block, facing)
        grid.use_surface()
        grid.covered.bind("COVERED")
        grid.class_buckets.write(bytes(4 * buckets * interleave))
        grid.class_buckets.bind_to_storage_buffer(STORAGE_BINDING["CLASS_BUCKETS"])
        grid.class_list.bind_to_storage_buffer(STORAGE_BINDING["CLASS_LIST"])
        self.classes.set(**grid.uniforms(), interleave=interleave, scatter=False)
        grid.dispatch(self.classes, grid.covered.count)
        counts = np.frombuffer(grid.class_buckets.read(4 * buckets * interleave), dtype="u4").astype(np.int64)
        firsts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        grid.class_buckets.write(firsts.astype("u4").tobytes())
        self.classes.set(scatter=True)
        grid.dispatch(self.classes, grid.covered.count)
        per_class = counts.reshape(interleave, buckets).sum(axis=1)
        grid.class_segments = [(int(firsts[c * buckets]), int(per_class[c])) for c in range(interleave)]
        grid.classes_for = (grid.version, interleave)

    def run(self, grid, cone_uniforms, out, segment):
        """Gather the voxels of class-list `segment` (first, count) into volume `out`."""
        grid.use_surface()
        grid.use_faces()
        grid.class_list.bind_to_storage_buffer(STORAGE_BINDING["CLASS_LIST"])
        bind_image(out, IMAGE_UNIT["GATHERED_OUT"])
        first, count = segment
        self.program.set(**grid.uniforms(), **cone_uniforms, first=first, count=count)
        grid.dispatch(self.program, count)

    def extrapolate(self, grid, latest, older, gain):
        """older <- latest + (latest - older) * gain, per covered voxel."""
        latest.use(TEXTURE_UNIT["VOXEL_GATHERED"])
        bind_image(older, IMAGE_UNIT["GATHERED_OUT"], read=True)
        grid.covered.bind("COVERED")
        self.extrapolate_program.set(**grid.uniforms(), gain=tuple(float(g) for g in gain))
        grid.dispatch(self.extrapolate_program, grid.covered.count)

    def copy(self, grid, source, target):
        """target <- source, per covered voxel: the extrapolation with gain 0."""
        self.extrapolate(grid, source, target, (0.0, 0.0, 0.0))

    def release(self):
        for handle in (self.program, self.classes, self.extrapolate_program):
            handle.release()
