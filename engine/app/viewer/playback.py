"""The viewer's animation clock (GL-free): which of the scene's animations play, whether they
play, how fast, and the time the scene is posed at (Scene.pose_at)."""

SPEED_RANGE = (0.1, 4.0)


class Playback:
    def __init__(self, durations):
        self.durations = dict(durations)  # {animation name: seconds}, as Scene.animations()
        self.animation = None             # the name that plays; None: all of them together
        self.playing = bool(self.durations)
        self.speed = 1.0
        self.time = 0.0                   # seconds, within 0..duration
        self._posed = None                # (time, animation) the scene was last posed at

    @property
    def duration(self):
        """The loop's length: the longest of the animations that play (0 without any)."""
        names = list(self.durations) if self.animation is None else [self.animation]
        return max((self.durations[name] for name in names), default=0.0)

    def advance(self, seconds):
        """While playing, move the time on by `seconds` of wall clock times the speed, looping."""
        if self.playing and self.duration > 0:
            self.time = (self.time + seconds * self.speed) % self.duration

    def seek(self, time):
        self.time = min(max(float(time), 0.0), self.duration)

    def choose(self, animation):
        """Play `animation` (a name of `durations`, or None for all), from the same time within
        its loop."""
        self.animation = animation
        self.seek(self.time % self.duration if self.duration > 0 else 0.0)

    def pose(self, scene):
        """Pose `scene` at the time, where the time or the animation changed since the last
        pose; returns whether it did."""
        wanted = (self.time, self.animation)
        if not self.durations or wanted == self._posed:
            return False
        scene.pose_at(*wanted)
        self._posed = wanted
        return True
