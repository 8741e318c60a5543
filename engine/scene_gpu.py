"""GPU copies of the scene's meshes: vertex and index buffers per mesh (uploaded once, released
when the mesh leaves the scene) and vertex arrays per program."""
import numpy as np

from . import transforms


class SceneGeometry:
    def __init__(self, ctx):
        self.ctx = ctx
        self.buffers = {}  # id(mesh) -> (the mesh's arrays, vbo, ibo)
        self.vertex_arrays = {}  # handle -> (program, {id(mesh): vao})
        self.draw_calls = 0

    def _buffers(self, mesh):
        """The mesh's buffers, uploaded again when it holds new arrays."""
        entry = self.buffers.get(id(mesh))
        if entry is not None and not all(a is b for a, b in zip(entry[0], mesh.arrays())):
            self._release_mesh(id(mesh))
            entry = None
        if entry is None:
            data = np.hstack([mesh.positions, mesh.normals]).astype("f4")
            entry = (mesh.arrays(), self.ctx.buffer(data.tobytes()), self.ctx.buffer(mesh.indices.astype("i4").tobytes()))
            self.buffers[id(mesh)] = entry
        return entry

    def vertex_array(self, handle, mesh):
        program, arrays = self.vertex_arrays.get(handle, (None, {}))
        if program is not handle.program:
            for vao in arrays.values():
                vao.release()
            program, arrays = handle.program, {}
            self.vertex_arrays[handle] = (program, arrays)
        _, vbo, ibo = self._buffers(mesh)  # uploaded again, without vertex arrays, if the mesh has new arrays
        vao = arrays.get(id(mesh))
        if vao is None:
            if "in_normal" in program:
                layout = (vbo, "3f 3f", "in_position", "in_normal")
            else:  # the compiler removed the unused normal: skip its 12 bytes
                layout = (vbo, "3f 12x", "in_position")
            vao = self.ctx.vertex_array(program, [layout], index_buffer=ibo)
            arrays[id(mesh)] = vao
        return vao

    def draw(self, handle, draws, per_draw=None):
        """Draw each of `draws` (changes.Draw) with `handle`; `per_draw(draw)` sets its uniforms."""
        for draw in draws:
            handle.set(model=transforms.gl_bytes(draw.world),
                       normal_matrix=np.asarray(transforms.normal_matrix(draw.world), "f4").T.tobytes())
            if per_draw is not None:
                per_draw(draw)
            self.vertex_array(handle, draw.mesh).render(self.ctx.TRIANGLES)
            self.draw_calls += 1

    def retain(self, draws):
        """Release the buffers and vertex arrays of meshes that no draw uses any more."""
        live = {id(d.mesh) for d in draws}
        for key in [k for k in self.buffers if k not in live]:
            self._release_mesh(key)

    def _release_mesh(self, key):
        for _, arrays in self.vertex_arrays.values():
            vao = arrays.pop(key, None)
            if vao is not None:
                vao.release()
        _, vbo, ibo = self.buffers.pop(key)
        vbo.release()
        ibo.release()

    def release(self):
        for _, arrays in self.vertex_arrays.values():
            for vao in arrays.values():
                vao.release()
        for _, vbo, ibo in self.buffers.values():
            vbo.release()
            ibo.release()
        self.vertex_arrays.clear()
        self.buffers.clear()
