"""Where the viewer's window puts the image and the panels (GL-free).

The panels stand in two columns beside the image, never over it: on the left the overlay
(the frame's figures) above the Scene Graph, on the right the Inspector, the Renderer panel
and, for an animated scene, the Animation panel. The image is drawn texel for texel at the
renderer's size, centred in the room the columns leave. A window too small for the columns
beside an image of MIN_IMAGE pixels shows the image alone.

Rectangles are in window pixels, (x, y) the top-left corner, y downwards (ImGui's convention).
"""
from dataclasses import dataclass

MARGIN = 8                  # between panels, and between a panel and the window's edge
LEFT_COLUMN = 264           # overlay and Scene Graph
RIGHT_COLUMN = 296          # Inspector, Renderer, Animation
OVERLAY_MAX_HEIGHT = 392    # the overlay's longest text (a first frame running every pass)
RENDERER_HEIGHT = 262       # the Renderer panel's widgets in every mode
ANIMATION_HEIGHT = 116      # the Animation panel's four rows
PANELS_MIN_HEIGHT = 640     # the least window height the columns are shown at
MIN_IMAGE = 64              # the least image width the columns leave room for


@dataclass(frozen=True)
class Rect:
    x: int
    y: int
    width: int
    height: int

    def overlaps(self, other):
        return (self.x < other.x + other.width and other.x < self.x + self.width
                and self.y < other.y + other.height and other.y < self.y + self.height)

    def contains(self, other):
        return (self.x <= other.x and other.x + other.width <= self.x + self.width
                and self.y <= other.y and other.y + other.height <= self.y + self.height)


@dataclass(frozen=True)
class Layout:
    window: Rect
    image: Rect     # where the frame is drawn
    panels: dict    # panel name -> its Rect (the overlay's: the most it grows to); {} when hidden

    @property
    def shows_panels(self):
        return bool(self.panels)


def panels_fit(window_size):
    """Whether the window has room for the columns beside an image of MIN_IMAGE pixels."""
    return window_size[0] >= LEFT_COLUMN + MIN_IMAGE + RIGHT_COLUMN and window_size[1] >= PANELS_MIN_HEIGHT


def image_area(window_size, show_panels):
    """The part of the window the image may use: between the columns when they are shown."""
    width, height = window_size
    if show_panels and panels_fit(window_size):
        return Rect(LEFT_COLUMN, 0, width - LEFT_COLUMN - RIGHT_COLUMN, height)
    return Rect(0, 0, width, height)


def window_size_for(image_size, show_panels):
    """The window that holds an image of `image_size` and, when shown, the columns beside it."""
    if not show_panels:
        return tuple(image_size)
    return (LEFT_COLUMN + max(image_size[0], MIN_IMAGE) + RIGHT_COLUMN, max(image_size[1], PANELS_MIN_HEIGHT))


def layout(window_size, image_size, show_panels, animated):
    """The image's and each shown panel's rectangle in a window of `window_size`."""
    area = image_area(window_size, show_panels)
    image = Rect(area.x + max(area.width - image_size[0], 0) // 2, area.y + max(area.height - image_size[1], 0) // 2,
                 *image_size)
    window = Rect(0, 0, *window_size)
    if area == window:
        return Layout(window, image, {})
    height = window_size[1]
    left = MARGIN
    left_width = LEFT_COLUMN - 2 * MARGIN
    below_overlay = MARGIN + OVERLAY_MAX_HEIGHT + MARGIN
    panels = {
        "Overlay": Rect(left, MARGIN, left_width, OVERLAY_MAX_HEIGHT),
        "Scene Graph": Rect(left, below_overlay, left_width, height - below_overlay - MARGIN),
    }
    right = window_size[0] - RIGHT_COLUMN + MARGIN
    right_width = RIGHT_COLUMN - 2 * MARGIN
    bottom = height - MARGIN  # the right column fills from the bottom up
    if animated:
        bottom -= ANIMATION_HEIGHT
        panels["Animation"] = Rect(right, bottom, right_width, ANIMATION_HEIGHT)
        bottom -= MARGIN
    bottom -= RENDERER_HEIGHT
    panels["Renderer"] = Rect(right, bottom, right_width, RENDERER_HEIGHT)
    panels["Inspector"] = Rect(right, MARGIN, right_width, bottom - 2 * MARGIN)
    return Layout(window, image, panels)
