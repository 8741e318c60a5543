"""G-buffer inspection views: albedo, normals (encoded 0.5 n + 0.5), depth / far plane."""
from ..core.constants import SHADER_ENUMS
from .target import FullScreenPass


class GBufferViewPass(FullScreenPass):
    FRAGMENT_SHADER = "gbuffer_view/show_gbuffer.frag"
    READS = ("TEX_GBUF_POSITION", "TEX_GBUF_NORMAL", "TEX_GBUF_ALBEDO", "UBO_CAMERA")

    def render(self, gbuffer, view, camera):
        self.program.set(view=SHADER_ENUMS["VIEW"][view], far_plane=float(camera.far))
        return self.draw(**gbuffer.resources("GBUF_POSITION", "GBUF_NORMAL", "GBUF_ALBEDO"), **camera.resources())
