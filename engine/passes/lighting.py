"""Deferred direct lighting: emission plus point/spot/directional lights with shadows, from the
G-buffer and the shadow maps into an HDR target."""
from .gbuffer import GBuffer
from .target import FullScreenPass


class LightingPass(FullScreenPass):
    FRAGMENT_SHADER = "lighting/shade_lights.frag"
    READS = (*GBuffer.READS, "TEX_SHADOW_ATLAS", "UBO_LIGHTS", "UBO_SHADOW_VIEWS", "UBO_CAMERA")

    def render(self, gbuffer, shadow_maps, camera):
        """`camera`: frame.camera.FrameCamera."""
        self.program.set(**shadow_maps.uniforms())
        return self.draw(**gbuffer.resources(), **shadow_maps.resources(), **camera.resources())
