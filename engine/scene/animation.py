"""Node animations, evaluated in time (plain Python/numpy, no GL): glTF 2.0's translation,
rotation, scale and morph target weights channels with LINEAR, STEP and CUBICSPLINE samplers.

A node that an animation moves carries its `NodeTracks`: its rest pose and, per animation
name, a Sampler per animated property. `Scene.pose_at(t)` sets every such node to its pose at
t; what the node carries (its mesh, light or camera) moves with it. Before an animation's first
keyframe and after its last, a sampler holds the first and last value (glTF's clamping).
"""
from dataclasses import dataclass

import numpy as np

from ..core.transforms import euler_deg_from_rotation, quaternion_rotation

INTERPOLATIONS = ("LINEAR", "STEP", "CUBICSPLINE")
PATHS = ("translation", "rotation", "scale", "weights")  # rotation: unit quaternions [x, y, z, w]


@dataclass(frozen=True, eq=False)
class Sampler:
    """Keyframes of one property: `times` (k,) seconds, strictly increasing; `values` (k, w),
    or (k, 3, w) for CUBICSPLINE (in-tangent, value, out-tangent per keyframe, tangents in
    units per second); `rotation`: the values are quaternions."""

    times: np.ndarray
    values: np.ndarray
    interpolation: str
    rotation: bool

    @property
    def duration(self):
        return float(self.times[-1])

    def _keyframe(self, i):
        return self.values[i, 1] if self.interpolation == "CUBICSPLINE" else self.values[i]

    def at(self, t):
        """The property's value at t seconds."""
        times = self.times
        if t <= times[0]:
            return self._keyframe(0).astype(float)
        if t >= times[-1]:
            return self._keyframe(-1).astype(float)
        i = int(np.searchsorted(times, t, side="right")) - 1
        span = float(times[i + 1] - times[i])
        u = (t - float(times[i])) / span
        if self.interpolation == "STEP":
            return self._keyframe(i).astype(float)
        if self.interpolation == "CUBICSPLINE":
            p0, m0 = self.values[i, 1].astype(float), span * self.values[i, 2]
            p1, m1 = self.values[i + 1, 1].astype(float), span * self.values[i + 1, 0]
            # Cubic Hermite spline (glTF 2.0, Appendix C)
            value = ((2 * u ** 3 - 3 * u ** 2 + 1) * p0 + (u ** 3 - 2 * u ** 2 + u) * m0
                     + (-2 * u ** 3 + 3 * u ** 2) * p1 + (u ** 3 - u ** 2) * m1)
            return value / np.linalg.norm(value) if self.rotation else value
        a, b = self.values[i].astype(float), self.values[i + 1].astype(float)
        return slerp(a, b, u) if self.rotation else a + u * (b - a)


def slerp(a, b, u):
    """Spherical linear interpolation of unit quaternions a -> b along the shorter arc."""
    cos_angle = float(np.dot(a, b))
    if cos_angle < 0.0:
        b, cos_angle = -b, -cos_angle
    if cos_angle > 0.9995:  # nearly parallel: the chord is the arc
        q = a + u * (b - a)
        return q / np.linalg.norm(q)
    angle = np.arccos(cos_angle)
    return (np.sin((1.0 - u) * angle) * a + np.sin(u * angle) * b) / np.sin(angle)


@dataclass(frozen=True, eq=False)
class NodeTracks:
    """What animates one node: its rest pose (translation, rotation_deg, scale, morph weights
    or None), which the properties an animation does not move keep, and {animation name:
    {path: Sampler}}."""

    rest: tuple
    tracks: dict

    def pose(self, t, names):
        """(translation, rotation_deg, scale, morph weights or None) at t seconds of the
        animations `names`."""
        translation, rotation_deg, scale = (np.array(v, float) for v in self.rest[:3])
        weights = None if self.rest[3] is None else np.array(self.rest[3], float)
        for name in names:
            samplers = self.tracks.get(name, {})
            if "translation" in samplers:
                translation = samplers["translation"].at(t)
            if "rotation" in samplers:
                rotation_deg = euler_deg_from_rotation(quaternion_rotation(samplers["rotation"].at(t)))
            if "scale" in samplers:
                scale = samplers["scale"].at(t)
            if "weights" in samplers:
                weights = samplers["weights"].at(t)
        return translation, rotation_deg, scale, weights

    def durations(self):
        """{animation name: the last keyframe time of its samplers of this node}."""
        return {name: max(s.duration for s in samplers.values()) for name, samplers in self.tracks.items()}
