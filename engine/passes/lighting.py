"""Deferred direct lighting: emission plus point/spot/directional lights with shadows, into an
HDR target."""
from .target import ScreenTarget


class LightingPass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="fullscreen.vert", fragment_shader="lighting.frag")
        self.target = ScreenTarget(ctx, size)

    def resize(self, size):
        self.target.resize(size)

    def render(self, camera_position):
        self.program.set(camera_position=tuple(camera_position))
        self.target.draw(self.program)

    def release(self):
        self.target.release()
        self.program.release()
