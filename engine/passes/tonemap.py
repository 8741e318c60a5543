"""Tone mapping: exposure, a tone curve and sRGB encoding into an 8-bit target."""
from ..core.constants import SHADER_ENUMS
from ..gpu.bindings import bind_texture
from .target import ScreenTarget


class TonemapPass:
    def __init__(self, ctx, programs, size):
        self.program = programs.program(vertex_shader="lib/fullscreen.vert", fragment_shader="tonemap/tone_map.frag",
                                        reads=("TEX_HDR_INPUT",))
        self.target = ScreenTarget(ctx, size, dtype="f1")

    def resize(self, size):
        self.target.resize(size)

    def render(self, hdr_texture, exposure, tonemap, encode_srgb=True):
        bind_texture(hdr_texture, "HDR_INPUT")
        self.program.set(exposure=float(exposure), tonemap=SHADER_ENUMS["TONEMAP"][tonemap], encode_srgb=bool(encode_srgb))
        self.target.draw(self.program)
        return self.target

    def release(self):
        self.target.release()
        self.program.release()
