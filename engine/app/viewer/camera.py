"""A fly camera over the scene's Camera: move along the view axes, turn by mouse, no GL.

The viewer feeds it one frame of input (`move` in view axes, `turn` in pixels, `scroll` in
wheel steps) and writes it back with `apply(scene.camera)`. Turning keeps the scene camera's
`up` as the world up, so yaw never rolls the horizon. Where the scene's camera moves (an
animated glTF camera), `follow` makes its view the home view: it shows until the user moves
the camera, and R goes back to it.
"""
import math

import numpy as np

TURN_DEGREES_PER_PIXEL = 0.2
SPEED_STEP = 1.25          # one wheel step multiplies (or divides) the speed by this
FAST_FACTOR = 4.0          # speed multiplier while Shift is held
MIN_ANGLE_TO_UP_DEG = 1.0  # pitch stops this close to straight up or down
MAX_FRAME_SECONDS = 0.25   # a slow frame moves at most this much time's worth


def _rotate(vector, axis, degrees):
    """Rodrigues' rotation of `vector` about the unit `axis`."""
    a = math.radians(degrees)
    return (vector * math.cos(a) + np.cross(axis, vector) * math.sin(a)
            + axis * np.dot(axis, vector) * (1.0 - math.cos(a)))


def _unit(vector):
    return vector / np.linalg.norm(vector)


class FlyCamera:
    def __init__(self, camera, scene_size=2.0):
        self._home = (np.array(camera.position, float), np.array(camera.look_at, float))
        self.up = _unit(np.array(camera.up, float))
        self.base_speed = max(float(scene_size), 1e-3) * 0.5  # scene units per second
        self.reset()

    def reset(self):
        """Back to the scene's view and the default speed."""
        self._go_home()
        self.speed = self.base_speed
        self.moved = False  # True once the view differs from the scene's

    def _go_home(self):
        position, look_at = self._home
        self.position = position.copy()
        self.forward = _unit(look_at - position)
        self.focus_distance = float(np.linalg.norm(look_at - position))

    def follow(self, camera):
        """The scene's camera moved (its animation): its view is the home view from now on,
        and the fly camera's own until the user moves it."""
        self._home = (np.array(camera.position, float), np.array(camera.look_at, float))
        if not self.moved:
            self.up = _unit(np.array(camera.up, float))
            self._go_home()

    @property
    def right(self):
        return _unit(np.cross(self.forward, self.up))

    def update(self, dt, move=(0.0, 0.0, 0.0), turn=(0.0, 0.0), scroll=0.0, fast=False):
        """One frame of input: `move` = (right, up, forward) in -1..1, `turn` = mouse pixels
        (x right, y down), `scroll` = wheel steps (speed), `fast` = Shift held."""
        if scroll:
            self.speed *= SPEED_STEP ** float(scroll)
        if turn[0] or turn[1]:
            self.turn(turn[0] * TURN_DEGREES_PER_PIXEL, turn[1] * TURN_DEGREES_PER_PIXEL)
        if any(move):
            step = self.speed * (FAST_FACTOR if fast else 1.0) * min(max(dt, 0.0), MAX_FRAME_SECONDS)
            self.position = self.position + step * (move[0] * self.right + move[1] * self.up + move[2] * self.forward)
            self.moved = True

    def turn(self, yaw_deg, pitch_deg):
        """Yaw right by `yaw_deg` about the world up, pitch down by `pitch_deg`."""
        right = self.right
        forward = _rotate(self.forward, self.up, -yaw_deg)
        pitched = _rotate(forward, right, -pitch_deg)
        angle_to_up = math.degrees(math.acos(np.clip(np.dot(_unit(pitched), self.up), -1.0, 1.0)))
        if MIN_ANGLE_TO_UP_DEG <= angle_to_up <= 180.0 - MIN_ANGLE_TO_UP_DEG:
            forward = pitched
        self.forward = _unit(forward)
        self.moved = True

    def apply(self, camera):
        """Write the fly camera's view into the scene camera (the renderer reads it)."""
        if not self.moved:
            camera.position, camera.look_at = self._home[0].copy(), self._home[1].copy()
            return
        camera.position = self.position.copy()
        camera.look_at = self.position + self.forward * self.focus_distance
        camera.up = self.up.copy()  # an animated camera's roll does not turn the user's view
