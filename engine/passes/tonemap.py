"""Tone mapping: exposure, a tone curve and sRGB encoding into an 8-bit target."""
from ..core.constants import SHADER_ENUMS
from ..gpu.bindings import bind_texture
from .target import FullScreenPass


class TonemapPass(FullScreenPass):
    FRAGMENT_SHADER = "tonemap/tone_map.frag"
    READS = ("TEX_HDR_INPUT",)
    TARGET_DTYPE = "f1"

    def render(self, hdr_texture, exposure, tonemap, encode_srgb=True):
        bind_texture(hdr_texture, "HDR_INPUT")
        self.program.set(exposure=float(exposure), tonemap=SHADER_ENUMS["TONEMAP"][tonemap], encode_srgb=bool(encode_srgb))
        return self.draw()
