"""A colour render target and the fullscreen-triangle draw that the screen-space passes share,
and the full-screen pass they are made from."""
import numpy as np

from ..gpu.bindings import program_used


class ScreenTarget:
    def __init__(self, ctx, size, components=4, dtype="f4"):
        self.ctx = ctx
        self.components, self.dtype = components, dtype
        self.texture = self.framebuffer = None
        self._vertex_arrays = {}
        self.resize(size)

    def resize(self, size):
        self._release_texture()
        self.size = size
        self.texture = self.ctx.texture(size, self.components, dtype=self.dtype)
        self.texture.filter = (self.ctx.NEAREST, self.ctx.NEAREST)
        self.framebuffer = self.ctx.framebuffer(color_attachments=[self.texture])

    def draw(self, handle, resources):
        """Run `handle`'s fragment shader over every pixel of the target, with its `resources`
        bound (ProgramHandle.bind)."""
        handle.bind(resources)
        program = handle.program
        vao = self._vertex_arrays.get(handle)
        if vao is None or vao[0] is not program:
            if vao is not None:
                vao[1].release()
            vao = (program, self.ctx.vertex_array(program, []))
            self._vertex_arrays[handle] = vao
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, *self.size)
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.BLEND)
        vao[1].render(self.ctx.TRIANGLES, vertices=3)
        program_used(program)

    def read(self):
        """Pixels as float32 (H, W, components), row 0 at the top (uint8 for 8-bit targets)."""
        dtype = {"f4": "f4", "f2": "f2", "f1": "u1"}[self.dtype]
        data = np.frombuffer(self.texture.read(), dtype=dtype).reshape(self.size[1], self.size[0], self.components)
        return data[::-1].astype("f4" if dtype != "u1" else "u1")

    def _release_texture(self):
        for resource in (self.framebuffer, self.texture):
            if resource is not None:
                resource.release()
        self.framebuffer = self.texture = None

    def release(self):
        for _, vao in self._vertex_arrays.values():
            vao.release()
        self._vertex_arrays.clear()
        self._release_texture()


class FullScreenPass:
    """A pass that runs one fragment shader (FRAGMENT_SHADER, reading READS) over every pixel of
    a target of its own (of TARGET_DTYPE); a subclass's render sets its uniforms and returns
    draw(what it reads)."""
    FRAGMENT_SHADER = None
    READS = ()
    TARGET_DTYPE = "f4"

    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="lib/fullscreen.vert", fragment_shader=self.FRAGMENT_SHADER,
                                        reads=self.READS)
        self.target = ScreenTarget(ctx, size, dtype=self.TARGET_DTYPE)

    def resize(self, size):
        self.target.resize(size)

    def draw(self, **resources):
        """Run the program over the target with its `resources` (READS, by binding name);
        returns the target."""
        self.target.draw(self.program, resources)
        return self.target

    def release(self):
        self.target.release()
        self.program.release()
