"""G-buffer inspection views: albedo, normals (encoded 0.5 n + 0.5), depth / far plane."""
from ..core.constants import SHADER_ENUMS
from .target import ScreenTarget


class GBufferViewPass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="lib/fullscreen.vert", fragment_shader="gbuffer_view/show_gbuffer.frag",
                                        reads=("TEX_GBUF_POSITION", "TEX_GBUF_NORMAL", "TEX_GBUF_ALBEDO", "UBO_CAMERA"))
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def render(self, gbuffer, view, camera):
        gbuffer.use()
        camera.bind()
        self.program.set(view=SHADER_ENUMS["VIEW"][view], far_plane=float(camera.far))
        self.target.draw(self.program)
        return self.target

    def release(self):
        self.target.release()
        self.program.release()
