"""Reference trajectories of a spatial platform pose ``(x, y, z, theta_x, theta_y, theta_z)``.

Pure NumPy; the spatial counterpart of :mod:`cdpr_exu.scenes.trajectories`. Pose convention
(:mod:`cdpr_exu.core.geometry`): ``(x, y, z)`` [m] is the position of the platform's centre
of mass, z up and gravity along -z, and ``theta = (theta_x, theta_y, theta_z)`` [rad]
is a rotation vector, ``R = exp([theta]x)`` (:func:`cdpr_exu.core.geometry.rotation_from_vector`).

Every trajectory offers ``pose(t)``, ``velocity(t)`` and ``acceleration(t)``: a scalar
time gives shape (6,), a time array of shape (N,) gives (N, 6) (any time shape ``S``
gives ``S + (6,)``).

``velocity`` is the time derivative of the 6-vector pose, ``(x', y', z', theta')``
[m/s, rad/s]: the rate of the rotation *vector*, NOT the angular velocity. The
angular velocity in the fixed frame is ``omega = J_l(theta) theta'``
(:func:`cdpr_exu.core.geometry.left_jacobian`); the two agree only while ``theta`` and
``theta'`` are parallel (e.g. about one fixed axis) or ``theta`` is 0. ``acceleration``
is the second derivative of the pose, ``(x'', y'', z'', theta'')``, likewise not the
angular acceleration.

Trajectories are frozen dataclasses that round-trip through plain dicts (``to_dict`` /
:func:`spatial_trajectory_from_dict`) for TOML scene files.

Relation to the planar module: a planar robot lives in the vertical x-z plane and
turns by ``phi`` counter-clockwise as seen with x to the right and z up
(:func:`cdpr_exu.core.geometry.rotation_matrix`). Seen that way the y axis (z = x cross y)
points *into* the page, so the planar rotation ``phi`` is the spatial rotation about
``-y``: the planar pose ``(x, z, phi)`` is the spatial pose ``(x, 0, z, 0, -phi, 0)``,
since ``rotation_from_vector((0, -phi, 0))`` restricted to the x-z rows and columns is
``rotation_matrix(phi)``. A planar :class:`~cdpr_exu.scenes.trajectories.CircleTrajectory`
is a vertical circle; :class:`SpatialCircleTrajectory` is horizontal, so the two are
not the same motion.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import shown
from cdpr_exu.scenes.trajectories import (PointToPointMotion, ReferenceTrajectory, _finite_float, _finite_tuple,
                                          _times, circle_phase, quarter_turn_times)

__all__ = [
    "SpatialTrajectory",
    "SpatialCircleTrajectory",
    "SpatialHoldTrajectory",
    "SpatialPointToPointTrajectory",
    "spatial_trajectory_from_dict",
]

POSE_SIZE = 6


def _stack(components, scalar):
    """Six arrays (broadcast together) as rows of the pose: shape t.shape + (6,), or (6,)."""
    out = np.stack(np.broadcast_arrays(*components), axis=-1)
    return out if not scalar else out.reshape(POSE_SIZE)


# ----------------------------------------------------------------------------------
# trajectories
# ----------------------------------------------------------------------------------
class SpatialTrajectory(ReferenceTrajectory):
    """A reference spatial platform pose as a function of time [s]."""

    @abstractmethod
    def pose(self, t):
        """Pose ``(x, y, z, theta_x, theta_y, theta_z)`` [m, rad]: shape (6,) for scalar t, (N, 6) for (N,)."""

    @abstractmethod
    def velocity(self, t):
        """Pose rate ``(x', y', z', theta')`` [m/s, rad/s]: (6,) or (N, 6).

        ``theta'`` is the rotation-vector rate, not the angular velocity (see the module docstring).
        """

    @abstractmethod
    def acceleration(self, t):
        """Second derivative of the pose [m/s^2, rad/s^2] (not the angular acceleration): (6,) or (N, 6)."""


@dataclass(frozen=True)
class SpatialCircleTrajectory(SpatialTrajectory):
    """Horizontal circle with an optional rocking tilt.

    ``x = c_x + R sin(p)``, ``y = c_y - R cos(p)``, ``z = c_z``, and rotation vector
    ``theta = rotation + tilt sin(p)``, with the phase ``p(t)`` of the planar
    :class:`~cdpr_exu.scenes.trajectories.CircleTrajectory` (same ``angular_rate`` and
    ``ramp_time``). The platform starts at ``(c_x, c_y - R, c_z)`` with orientation
    ``rotation``, moves counter-clockwise seen from above for ``angular_rate > 0``, and
    rocks once per turn.

    Parameters
    ----------
    center : tuple of 3 float [m]
        Circle centre ``(c_x, c_y, c_z)``; required (no position suits every robot).
    radius : float [m]
        Circle radius ``R >= 0`` (default 0.4, as the planar circle).
    angular_rate : float [rad/s]
        Steady phase rate ``w`` (default 1.5, as the planar circle; negative: clockwise).
    rotation : tuple of 3 float [rad]
        Constant base rotation vector (default 0: the platform level).
    tilt : tuple of 3 float [rad]
        Amplitude of the periodic rocking added to the rotation vector as
        ``tilt sin(p)``; keep it small (default 0: no rocking).
    ramp_time : float [s]
        0 (default, as the planar circle): ``p = w t``, which starts at full speed. If
        > 0, the phase rate rises from rest to ``w`` along the quintic ``w s(t / T)``,
        so that pose, velocity and acceleration are continuous and the start is from
        rest; after the ramp ``p = w (t - T / 2)``. Before t = 0 the pose holds the start.
    """

    center: tuple
    radius: float = 0.4
    angular_rate: float = 1.5
    rotation: tuple = (0.0, 0.0, 0.0)
    tilt: tuple = (0.0, 0.0, 0.0)
    ramp_time: float = 0.0
    kind = "circle"

    def __post_init__(self):
        object.__setattr__(self, "center", _finite_tuple("trajectory.center", self.center, 3))
        radius = _finite_float("trajectory.radius", self.radius)
        if radius < 0.0:
            raise SceneError(f"trajectory.radius must be >= 0 [m], got {shown(self.radius)}")
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "angular_rate", _finite_float("trajectory.angular_rate", self.angular_rate))
        object.__setattr__(self, "rotation", _finite_tuple("trajectory.rotation", self.rotation, 3))
        object.__setattr__(self, "tilt", _finite_tuple("trajectory.tilt", self.tilt, 3))
        ramp_time = _finite_float("trajectory.ramp_time", self.ramp_time)
        if ramp_time < 0.0:
            raise SceneError(f"trajectory.ramp_time must be >= 0 [s], got {shown(self.ramp_time)}")
        object.__setattr__(self, "ramp_time", ramp_time)

    def turning_times(self, end_time: float) -> np.ndarray:
        """Times where x, y or a rocking rotation component is extreme [s].

        The phase at a multiple of pi/2; none with a ramp (no closed form).
        """
        moves = self.radius != 0.0 or any(self.tilt)
        return quarter_turn_times(end_time, self.angular_rate, self.ramp_time, moves)

    def phase(self, t):
        """Phase ``p`` [rad] and its first two time derivatives, each of t's shape (as the planar circle)."""
        return circle_phase(t, self.angular_rate, self.ramp_time)

    def pose(self, t):
        t, scalar = _times(t)
        p, _, _ = self.phase(t)
        sin, cos = np.sin(p), np.cos(p)
        position = (self.center[0] + self.radius * sin, self.center[1] - self.radius * cos,
                    np.full_like(t, self.center[2]))
        turn = tuple(base + amplitude * sin for base, amplitude in zip(self.rotation, self.tilt))
        return _stack(position + turn, scalar)

    def velocity(self, t):
        t, scalar = _times(t)
        p, p_rate, _ = self.phase(t)
        sin, cos = np.sin(p), np.cos(p)
        position = (self.radius * cos * p_rate, self.radius * sin * p_rate, np.zeros_like(t))
        turn = tuple(amplitude * cos * p_rate for amplitude in self.tilt)
        return _stack(position + turn, scalar)

    def acceleration(self, t):
        t, scalar = _times(t)
        p, p_rate, p_acc = self.phase(t)
        sin, cos = np.sin(p), np.cos(p)
        along, across = cos * p_acc - sin * p_rate**2, sin * p_acc + cos * p_rate**2
        position = (self.radius * along, self.radius * across, np.zeros_like(t))
        turn = tuple(amplitude * along for amplitude in self.tilt)
        return _stack(position + turn, scalar)


@dataclass(frozen=True)
class SpatialHoldTrajectory(SpatialTrajectory):
    """A constant spatial pose.

    Parameters
    ----------
    held_pose : tuple of 6 float [m, m, m, rad, rad, rad]
        The held pose ``(x, y, z, theta_x, theta_y, theta_z)``; required; the key
        ``pose`` in dicts. (Not a field named ``pose``, which would hide the method;
        pass it positionally: ``SpatialHoldTrajectory((0, 0, 1, 0, 0, 0))``.)
    """

    held_pose: tuple
    kind = "hold"

    def __post_init__(self):
        object.__setattr__(self, "held_pose", _finite_tuple("trajectory.pose", self.held_pose, POSE_SIZE))

    def pose(self, t):
        t, _ = _times(t)
        return np.broadcast_to(np.asarray(self.held_pose), t.shape + (POSE_SIZE,)).copy()

    def velocity(self, t):
        t, _ = _times(t)
        return np.zeros(t.shape + (POSE_SIZE,))

    def acceleration(self, t):
        return self.velocity(t)

    def to_dict(self):
        return {"kind": self.kind, "pose": list(self.held_pose)}


@dataclass(frozen=True)
class SpatialPointToPointTrajectory(PointToPointMotion, SpatialTrajectory):
    """Rest-to-rest quintic motion from ``start`` to ``end``; holds outside the motion.

    ``pose(t) = start + (end - start) s((t - start_time) / duration)``, with
    ``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5`` (the planar module's blend): zero
    velocity and acceleration at both ends. The rotation vector is blended linearly,
    so the platform turns about one fixed axis only if ``start``'s and ``end``'s
    rotation vectors are parallel (or one is 0).

    Parameters
    ----------
    start, end : tuple of 6 float [m, m, m, rad, rad, rad]
        Initial and final pose; both required.
    duration : float [s]
        Motion time (> 0, default 1).
    start_time : float [s]
        Time at which the motion begins (default 0).
    """

    start: tuple
    end: tuple
    duration: float = 1.0
    start_time: float = 0.0
    kind = "point_to_point"

    def __post_init__(self):
        object.__setattr__(self, "start", _finite_tuple("trajectory.start", self.start, POSE_SIZE))
        object.__setattr__(self, "end", _finite_tuple("trajectory.end", self.end, POSE_SIZE))
        duration = _finite_float("trajectory.duration", self.duration)
        if duration <= 0.0:
            raise SceneError(f"trajectory.duration must be > 0 [s], got {shown(self.duration)}")
        object.__setattr__(self, "duration", duration)
        object.__setattr__(self, "start_time", _finite_float("trajectory.start_time", self.start_time))


#: Fields a spatial trajectory table must give, by kind (no default would be what the user meant).
REQUIRED_FIELDS = {"circle": ("center",), "hold": ("pose",), "point_to_point": ("start", "end")}

_WHAT = {
    "center": "a position x, y, z [m]",
    "pose": "a pose x, y, z [m], rotation vector [rad]",
    "start": "a pose x, y, z [m], rotation vector [rad]",
    "end": "a pose x, y, z [m], rotation vector [rad]",
}

_KINDS = {
    "circle": SpatialCircleTrajectory,
    "hold": SpatialHoldTrajectory,
    "point_to_point": SpatialPointToPointTrajectory,
}


def spatial_trajectory_from_dict(data):
    """Build a spatial trajectory from a dict with a ``kind`` key, as written by ``to_dict``.

    Parameters
    ----------
    data : mapping
        ``{"kind": "circle" | "hold" | "point_to_point", <fields>}``. Required:
        ``center`` (circle), ``pose`` (hold; the key is ``pose``, not the field name
        ``held_pose``), ``start`` and ``end`` (point_to_point); other missing fields take
        their defaults.

    Returns
    -------
    SpatialTrajectory

    Raises
    ------
    SceneError
        If ``kind`` is missing or unknown, a key is not a field of that kind, a required
        field is missing, or a value is invalid.
    """
    if not hasattr(data, "keys"):
        raise SceneError(f"trajectory must be a table (dict), got {shown(data)}")
    values = dict(data)
    kind = values.pop("kind", None)
    if not isinstance(kind, str) or kind not in _KINDS:
        raise SceneError(f"trajectory.kind must be one of {sorted(_KINDS)}, got {shown(kind)}")
    cls = _KINDS[kind]
    # the dict keys: the field names, except hold's ``pose`` (its field is held_pose)
    allowed = sorted("pose" if field.name == "held_pose" else field.name for field in dataclass_fields(cls))
    unknown = sorted(set(values) - set(allowed))
    if unknown:
        raise SceneError(f"trajectory of kind {shown(kind)} has unknown key(s) {unknown}; allowed: {allowed}")
    missing = [name for name in REQUIRED_FIELDS[kind] if name not in values]
    if missing:
        raise SceneError(f"trajectory.{missing[0]} is required for kind {shown(kind)} ({_WHAT[missing[0]]}); "
                         f"it has no sensible default")
    if cls is SpatialHoldTrajectory:
        values["held_pose"] = values.pop("pose")
    return cls(**values)
