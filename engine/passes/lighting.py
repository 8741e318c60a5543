"""Deferred direct lighting: emission plus point/spot/directional lights with shadows, from the
G-buffer and the shadow maps into an HDR target."""
from .gbuffer import GBuffer
from .target import ScreenTarget


class LightingPass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="lib/fullscreen.vert", fragment_shader="lighting/shade_lights.frag",
                                        reads=(*GBuffer.READS, "TEX_SHADOW_ATLAS", "UBO_LIGHTS", "UBO_SHADOW_VIEWS", "UBO_CAMERA"))
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def render(self, gbuffer, shadow_maps, camera):
        """`camera`: frame.camera.FrameCamera."""
        gbuffer.use()
        shadow_maps.bind(self.program)
        camera.bind()
        self.target.draw(self.program)
        return self.target

    def release(self):
        self.target.release()
        self.program.release()
