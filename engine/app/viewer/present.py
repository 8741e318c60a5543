"""Put the renderer's tone-mapped frame on the window: the window cleared to the panels'
background, then a texel-exact copy of the frame into its rectangle of the layout (a
triangle over that viewport), and a read-back of the whole window, panels included, for
window screenshots."""
import numpy as np

from ...gpu.bindings import bind_texture

_VERTEX = """
#version 450
void main() {
    vec2 corner = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
"""

_FRAGMENT = """
#version 450
uniform sampler2D frame;
uniform ivec2 origin;  // the viewport's lower-left corner in the window
out vec4 color;
void main() {
    color = vec4(texelFetch(frame, ivec2(gl_FragCoord.xy) - origin, 0).rgb, 1.0);
}
"""

FRAME_UNIT = 0
BACKGROUND = (0.1, 0.1, 0.1)


class Presenter:
    def __init__(self, ctx):
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=_VERTEX, fragment_shader=_FRAGMENT)
        self.program["frame"].value = FRAME_UNIT
        self.vertex_array = ctx.vertex_array(self.program, [])

    def draw(self, texture, rect, window_size):
        """Clear the window and copy `texture` (the frame) into `rect` (a layout.Rect of the
        frame's size, y downwards)."""
        self.ctx.screen.use()
        self.ctx.viewport = (0, 0, *window_size)
        self.ctx.clear(*BACKGROUND)
        origin = (rect.x, window_size[1] - rect.y - rect.height)  # GL counts rows from the bottom
        self.ctx.viewport = (*origin, rect.width, rect.height)
        self.program["origin"].value = origin
        self.ctx.disable(self.ctx.DEPTH_TEST | self.ctx.BLEND)
        bind_texture(texture, FRAME_UNIT)
        self.vertex_array.render(self.ctx.TRIANGLES, vertices=3)

    def read_window(self, size):
        """The window's back buffer as uint8 (H, W, 3), row 0 at the top (before the swap)."""
        self.ctx.screen.use()
        data = self.ctx.screen.read(viewport=(0, 0, *size), components=3, alignment=1)
        return np.frombuffer(data, np.uint8).reshape(size[1], size[0], 3)[::-1].copy()

    def release(self):
        self.vertex_array.release()
        self.program.release()
