"""Tone mapping: exposure, a tone curve and sRGB encoding into an 8-bit target."""
from ..core.constants import SHADER_ENUMS
from .target import FullScreenPass


class TonemapPass(FullScreenPass):
    FRAGMENT_SHADER = "tonemap/tone_map.frag"
    READS = ("TEX_HDR_INPUT",)
    TARGET_DTYPE = "f1"

    def render(self, hdr_texture, exposure, tonemap, encode_srgb=True):
        self.program.set(exposure=float(exposure), tonemap=SHADER_ENUMS["TONEMAP"][tonemap], encode_srgb=bool(encode_srgb))
        return self.draw(TEX_HDR_INPUT=hdr_texture)
