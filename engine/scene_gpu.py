"""GPU copies of the scene's meshes, and the per-draw data read from the scene every frame."""
import numpy as np

from . import transforms


class SceneGeometry:
    """Vertex/index buffers per mesh (uploaded once) and vertex arrays per program."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.buffers = {}  # id(mesh) -> (mesh, vbo, ibo)
        self.vertex_arrays = {}  # handle -> (program, {id(mesh): vao})
        self.draw_calls = 0

    def _buffers(self, mesh):
        entry = self.buffers.get(id(mesh))
        if entry is None or entry[0] is not mesh:
            data = np.hstack([mesh.positions, mesh.normals]).astype("f4")
            entry = (mesh, self.ctx.buffer(data.tobytes()), self.ctx.buffer(mesh.indices.astype("i4").tobytes()))
            self.buffers[id(mesh)] = entry
        return entry

    def vertex_array(self, handle, mesh):
        program, arrays = self.vertex_arrays.get(handle, (None, {}))
        if program is not handle.program:
            for vao in arrays.values():
                vao.release()
            program, arrays = handle.program, {}
            self.vertex_arrays[handle] = (program, arrays)
        vao = arrays.get(id(mesh))
        if vao is None:
            _, vbo, ibo = self._buffers(mesh)
            if "in_normal" in program:
                layout = (vbo, "3f 3f", "in_position", "in_normal")
            else:  # the compiler removed the unused normal: skip its 12 bytes
                layout = (vbo, "3f 12x", "in_position")
            vao = self.ctx.vertex_array(program, [layout], index_buffer=ibo)
            arrays[id(mesh)] = vao
        return vao

    def draw(self, handle, scene, per_draw=None, mode=None):
        """Draw every mesh of the scene with `handle`; `per_draw(node, world)` sets its uniforms."""
        for node, world in scene.drawables():
            handle.set(model=transforms.gl_bytes(world),
                       normal_matrix=np.asarray(transforms.normal_matrix(world), "f4").T.tobytes())
            if per_draw is not None:
                per_draw(node, world)
            self.vertex_array(handle, node.mesh).render(mode if mode is not None else self.ctx.TRIANGLES)
            self.draw_calls += 1

    def release(self):
        for _, arrays in self.vertex_arrays.values():
            for vao in arrays.values():
                vao.release()
        for _, vbo, ibo in self.buffers.values():
            vbo.release()
            ibo.release()
        self.vertex_arrays.clear()
        self.buffers.clear()
