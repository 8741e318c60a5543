"""Posing: skinned and morphed draws posed on the GPU, so that the G-buffer, the shadow maps and
the voxelizer draw them posed with the programs every draw uses.

Each posed draw has a copy of its mesh of its own in the mesh pool (MeshPool.posed_entry),
which this pass alone writes: glsl/pose/pose_vertices.comp reads the mesh's rest copy, blends
its morph targets by the draw's weights and skins it by the draw's joint matrices (the scene
table's DrawPose), and writes the copy; the copy's clusters take the box the table bounds the
pose by, for culling. A draw is posed again when the table says its geometry changed (a joint
moved, its weights were edited), and every posed draw when the pool was packed anew. Per mesh,
its influences and displacements are uploaded once. It keeps each posed vertex's position at
the frame before (`previous`, per vertex of the pool: temporal anti-aliasing's motion), and
so runs at the frame after a pose too, which moves nothing (`holding`)."""
import math

import numpy as np

from ..core.constants import LIST_GROUP, struct_dtype
from .cull import buffer_holding

INFLUENCE_DTYPE = struct_dtype("PoseInfluence")


class PosePass:
    def __init__(self, ctx, programs):
        self.ctx = ctx
        self.program = programs.compute(
            "pose/pose_vertices.comp", reads=("SSBO_POSE_INFLUENCES", "SSBO_POSE_TARGETS", "SSBO_POSE_MATRICES", "SSBO_POSE_WEIGHTS"),
            writes=("SSBO_POSE_VERTICES", "SSBO_POSE_PREVIOUS"))
        self.meshes = {}  # id(Mesh) -> (its arrays, influences buffer, displacements buffer, influence sets)
        self.matrices = ctx.buffer(reserve=64)
        self.weights = ctx.buffer(reserve=16)
        self.posed_at = None  # (table structure, pool epoch, table stamp) of the last run
        self.previous = ctx.buffer(reserve=16)  # vec4 per vertex of the pool
        self.posed_last = np.zeros(0, np.int64)  # the draws the last run posed: at the next, not yet still
    def due(self, table, buffers):
        """The draws of `table` whose pose changed since the last run (every posed draw after
        the table was built or the pool packed anew)."""
        if self._continued(table, buffers):
            return table.posed_draws[table.geometry_stamp[table.posed_draws] > self.posed_at[2]]
        return table.posed_draws

    def busy(self, draws, motion):
        """Whether a frame whose due draws are `draws` has work here: those, or, where the frame
        wants the motion, the draws the last run posed, whose previous positions become their
        positions."""
        return len(draws) > 0 or (motion and len(self.posed_last) > 0)

    def _continued(self, table, buffers):
        """Whether the pool's posed copies are those of the last run (no new table, no packing)."""
        return self.posed_at is not None and self.posed_at[:2] == (table.structure, buffers.pool.epoch)

    def run(self, table, buffers, draws, motion):
        """Pose `draws` (due) of `table` into their copies in `buffers`' pool; where the frame
        wants the `motion`, keeping their positions before, and the draws posed by the last run
        and not now keep their positions as the previous ones."""
        pool = buffers.pool
        fresh = not (motion and self._continued(table, buffers))
        if self.posed_at is None or self.posed_at[0] != table.structure:  # the meshes no draw poses any more
            live = {id(table.meshes[table.draw_mesh[draw]]) for draw in table.posed_draws}
            for key in [key for key in self.meshes if key not in live]:
                for buffer in self.meshes.pop(key)[1:3]:
                    buffer.release()
        if self.previous.size < 16 * pool.vertex_room:
            self.previous.release()
            self.previous = self.ctx.buffer(reserve=16 * pool.vertex_room)
            fresh = True
        self.posed_at = (table.structure, pool.epoch, table.stamp)
        held = np.zeros(0, np.int64) if fresh else np.setdiff1d(self.posed_last, draws)
        self.posed_last = np.asarray(draws, np.int64)
        for draw in held:
            posed = buffers.draw_entries[draw]
            count = len(table.meshes[table.draw_mesh[draw]].positions)
            self.program.set(vertex_count=count, posed_first=posed.base_vertex, holding=True, fresh=False)
            self.program.run(math.ceil(count / LIST_GROUP), SSBO_POSE_VERTICES=pool.vertices, SSBO_POSE_PREVIOUS=self.previous,
                             SSBO_POSE_INFLUENCES=None, SSBO_POSE_TARGETS=None, SSBO_POSE_MATRICES=None, SSBO_POSE_WEIGHTS=None)
        if not len(draws):
            self.ctx.memory_barrier(self.ctx.SHADER_STORAGE_BARRIER_BIT)
            return
        poses = [table.pose(draw) for draw in draws]
        matrices = [pose.matrices for pose in poses if pose.matrices is not None]
        weights = [pose.weights for pose in poses if pose.weights is not None]
        if matrices:
            self.matrices = buffer_holding(self.ctx, self.matrices, np.concatenate(matrices).transpose(0, 2, 1).astype("f4"), keep=True)
        if weights:
            self.weights = buffer_holding(self.ctx, self.weights, np.concatenate(weights).astype("f4"), keep=True)
        first_matrix = first_weight = 0
        for draw, pose in zip(draws, poses):
            mesh = table.meshes[table.draw_mesh[draw]]
            influences, displacements, sets = self._mesh_data(mesh, skinned=pose.matrices is not None)
            rest, posed = pool.entries[id(mesh)], buffers.draw_entries[draw]
            count = len(mesh.positions)
            self.program.set(vertex_count=count, rest_first=rest.base_vertex, posed_first=posed.base_vertex,
                             influence_sets=sets, target_count=0 if pose.weights is None else len(pose.weights),
                             first_matrix=first_matrix, first_weight=first_weight, holding=False, fresh=fresh)
            self.program.run(math.ceil(count / LIST_GROUP), SSBO_POSE_VERTICES=pool.vertices, SSBO_POSE_PREVIOUS=self.previous,
                             SSBO_POSE_INFLUENCES=influences,
                             SSBO_POSE_TARGETS=displacements, SSBO_POSE_MATRICES=self.matrices, SSBO_POSE_WEIGHTS=self.weights)
            pool.set_cluster_bounds(posed, *pose.box)
            first_matrix += 0 if pose.matrices is None else len(pose.matrices)
            first_weight += 0 if pose.weights is None else len(pose.weights)
        self.ctx.memory_barrier(self.ctx.VERTEX_ATTRIB_ARRAY_BARRIER_BIT | self.ctx.SHADER_STORAGE_BARRIER_BIT)

    def _mesh_data(self, mesh, skinned):
        """(influences, displacements, influence sets) of a mesh, uploaded once for its arrays."""
        held = self.meshes.get(id(mesh))
        if held is not None and all(a is b for a, b in zip(held[0], mesh.arrays())):
            return held[1:]
        if held is not None:
            held[1].release()
            held[2].release()
        count = len(mesh.positions)
        sets = mesh.joints.shape[1] // 4 if skinned else 0
        influences = np.zeros(max(count * sets, 1), INFLUENCE_DTYPE)
        if sets:
            influences["joints"] = np.asarray(mesh.joints, np.uint32).reshape(count * sets, 4)
            influences["weights"] = np.asarray(mesh.weights, np.float32).reshape(count * sets, 4)
        displacements = np.zeros((max(len(mesh.targets), 1), count, 3, 4), np.float32)
        for t, target in enumerate(mesh.targets):
            for k, values in enumerate((target.positions, target.normals, target.tangents)):
                if values is not None:
                    displacements[t, :, k, :3] = values
        data = (mesh.arrays(), self.ctx.buffer(influences.tobytes()), self.ctx.buffer(displacements.tobytes()), sets)
        self.meshes[id(mesh)] = data
        return data[1:]

    def resources(self):
        """The posed vertices' previous positions, as the G-buffer's motion reads them."""
        return {"SSBO_POSE_PREVIOUS": self.previous}

    def memory_bytes(self):
        return self.previous.size + self.matrices.size + self.weights.size + sum(held[1].size + held[2].size for held in self.meshes.values())

    def release(self):
        for held in self.meshes.values():
            held[1].release()
            held[2].release()
        self.meshes = {}
        self.matrices.release()
        self.weights.release()
        self.previous.release()

