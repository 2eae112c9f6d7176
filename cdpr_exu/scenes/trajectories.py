"""Reference trajectories of the platform pose ``(x, z, phi)``.

Pure NumPy. Every trajectory offers ``pose(t)``, ``velocity(t)`` and
``acceleration(t)``: a scalar time gives shape (3,), a time array of shape (N,) gives
(N, 3) (any time shape ``S`` gives ``S + (3,)``). Units: [m, m, rad] and their time
derivatives. Trajectories are frozen dataclasses that round-trip through plain dicts
(``to_dict`` / :func:`trajectory_from_dict`) for TOML scene files.

The paper's reference (scenario 1) is ``CircleTrajectory()``:
``r_ref(t) = (0.4 sin 1.5t, -1.6 - 0.4 cos 1.5t)`` [m], orientation 0.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import finite, shown

__all__ = [
    "Trajectory",
    "CircleTrajectory",
    "HoldTrajectory",
    "PointToPointTrajectory",
    "trajectory_from_dict",
]


# ----------------------------------------------------------------------------------
# argument checks
# ----------------------------------------------------------------------------------
def _finite_float(name, value):
    """``value`` as a finite float: the scenes' one number check (text and booleans refused)."""
    return finite(name, value)


def _finite_tuple(name, value, size):
    try:
        items = tuple(value)
    except TypeError as exc:
        raise SceneError(f"{name} must be a sequence of {size} numbers, got {shown(value)}") from exc
    if len(items) != size:
        raise SceneError(f"{name} must have {size} entries, got {shown(value)}")
    return tuple(_finite_float(f"{name}[{i}]", item) for i, item in enumerate(items))


def _times(t):
    """Time(s) as a float array, and whether the input was a scalar."""
    array = np.asarray(t, dtype=float)
    return array, array.ndim == 0


def _stack(x, z, phi, scalar):
    out = np.stack(np.broadcast_arrays(x, z, phi), axis=-1)
    return out if not scalar else out.reshape(3)


# ----------------------------------------------------------------------------------
# quintic blend s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 on [0, 1]: rest to rest, C2
# ----------------------------------------------------------------------------------
def _quintic(tau):
    """Blend value and its first two derivatives w.r.t. ``tau``; clamped outside [0, 1]."""
    tau = np.clip(tau, 0.0, 1.0)
    value = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    first = 30.0 * tau**2 * (1.0 - tau) ** 2
    second = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau)
    return value, first, second


def _quintic_integral(tau):
    """``int_0^tau s`` = 2.5 tau^4 - 3 tau^5 + tau^6 for tau in [0, 1]; 0.5 + (tau - 1) beyond."""
    clipped = np.clip(tau, 0.0, 1.0)
    inside = clipped**4 * (2.5 - 3.0 * clipped + clipped**2)
    return inside + np.maximum(tau - 1.0, 0.0)


# ----------------------------------------------------------------------------------
# trajectories
# ----------------------------------------------------------------------------------
class ReferenceTrajectory(ABC):
    """What every reference trajectory has, planar (:class:`Trajectory`) or spatial
    (:class:`~cdpr_exu.scenes.spatial_trajectories.SpatialTrajectory`): its turning times
    and its plain-dict form."""

    kind: str = ""

    def turning_times(self, end_time: float) -> np.ndarray:
        """Times in [0, end_time] [s] where a pose coordinate may be extreme (for exact workspace checks).

        The default is none: a uniform sampling of the run is used alone.
        """
        return np.zeros(0)

    def to_dict(self):
        """Plain dict with a ``kind`` key and the fields (tuples as lists), for TOML."""
        data = {"kind": self.kind}
        for field in dataclass_fields(self):
            value = getattr(self, field.name)
            data[field.name] = list(value) if isinstance(value, tuple) else value
        return data


class Trajectory(ReferenceTrajectory):
    """A reference planar platform pose as a function of time [s]."""

    @abstractmethod
    def pose(self, t):
        """Pose ``(x, z, phi)`` [m, m, rad]: shape (3,) for scalar t, (N, 3) for t of shape (N,)."""

    @abstractmethod
    def velocity(self, t):
        """Pose rate [m/s, m/s, rad/s]: shape (3,) or (N, 3)."""

    @abstractmethod
    def acceleration(self, t):
        """Second derivative of the pose [m/s^2, m/s^2, rad/s^2]: shape (3,) or (N, 3)."""


def circle_phase(t, angular_rate: float, ramp_time: float):
    """Phase [rad] of a circle run at ``angular_rate`` [rad/s], and its first two time derivatives.

    With ``ramp_time`` [s] > 0 the rate rises from 0 along the quintic blend (C2 from
    rest); each output has t's shape.
    """
    t = np.asarray(t, dtype=float)
    if ramp_time == 0.0:
        return angular_rate * t, np.full_like(t, angular_rate), np.zeros_like(t)
    tau = t / ramp_time
    blend, blend_rate, _ = _quintic(tau)
    return (angular_rate * ramp_time * _quintic_integral(np.maximum(tau, 0.0)), angular_rate * blend,
            angular_rate * blend_rate / ramp_time)


#: Most quarter turns of a circle a reference check samples (25 000 turns): beyond, the
#: reference turns faster than any robot could follow, and the samples would not fit in memory.
MAX_QUARTER_TURNS = 100_000


def quarter_turn_times(end_time: float, angular_rate: float, ramp_time: float, moves: bool) -> np.ndarray:
    """Times [s] where a circle's phase is a multiple of pi/2, up to ``end_time``; none for a
    ramped (no closed form), standing or motionless (``moves`` false) circle.

    Raises
    ------
    SceneError
        Naming trajectory.angular_rate when the circle makes more than :data:`MAX_QUARTER_TURNS`
        quarter turns before ``end_time``.
    """
    if ramp_time > 0.0 or angular_rate == 0.0 or not moves:
        return np.zeros(0)
    quarter = 0.5 * np.pi / abs(angular_rate)
    if end_time / quarter > MAX_QUARTER_TURNS:
        raise SceneError(f"trajectory.angular_rate = {shown(angular_rate)} rad/s makes {end_time / quarter:.3g} quarter "
                         f"turns in {shown(end_time)} s, more than the {MAX_QUARTER_TURNS} a reference check samples "
                         "(a circle far faster than any robot)")
    return np.arange(0.0, end_time + 1e-12, quarter)


@dataclass(frozen=True)
class CircleTrajectory(Trajectory):
    """Circle ``x = c_x + R sin(theta)``, ``z = c_z - R cos(theta)`` at constant orientation.

    Defaults are the paper's reference, ``theta = 1.5 t``: the platform starts at the
    bottom of the circle, (0, -2) m, and moves counter-clockwise.

    Parameters
    ----------
    center : tuple of 2 float [m]
        Circle centre ``(c_x, c_z)``.
    radius : float [m]
        Circle radius ``R >= 0``.
    angular_rate : float [rad/s]
        Steady phase rate ``w`` (negative: clockwise). Smaller is more quasi-static.
    rotation : float [rad]
        Constant platform orientation ``phi``.
    ramp_time : float [s]
        0 (the paper): ``theta = w t``, which starts at full speed. If > 0, the phase
        rate rises from rest to ``w`` along the quintic ``w s(t / T)``, so that pose,
        velocity and acceleration are continuous and the start is from rest; after the
        ramp ``theta = w (t - T / 2)``. Before t = 0 the pose holds the start.
    """

    center: tuple = (0.0, -1.6)
    radius: float = 0.4
    angular_rate: float = 1.5
    rotation: float = 0.0
    ramp_time: float = 0.0
    kind = "circle"

    def __post_init__(self):
        object.__setattr__(self, "center", _finite_tuple("trajectory.center", self.center, 2))
        radius = _finite_float("trajectory.radius", self.radius)
        if radius < 0.0:
            raise SceneError(f"trajectory.radius must be >= 0 [m], got {shown(self.radius)}")
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "angular_rate", _finite_float("trajectory.angular_rate", self.angular_rate))
        object.__setattr__(self, "rotation", _finite_float("trajectory.rotation", self.rotation))
        ramp_time = _finite_float("trajectory.ramp_time", self.ramp_time)
        if ramp_time < 0.0:
            raise SceneError(f"trajectory.ramp_time must be >= 0 [s], got {shown(self.ramp_time)}")
        object.__setattr__(self, "ramp_time", ramp_time)

    def turning_times(self, end_time: float) -> np.ndarray:
        """Times where x or z is extreme: the phase at a multiple of pi/2 (no ramp), [s]."""
        return quarter_turn_times(end_time, self.angular_rate, self.ramp_time, self.radius != 0.0)

    def phase(self, t):
        """Phase ``theta`` [rad] and its first two time derivatives, each of t's shape."""
        return circle_phase(t, self.angular_rate, self.ramp_time)

    def pose(self, t):
        t, scalar = _times(t)
        theta, _, _ = self.phase(t)
        x = self.center[0] + self.radius * np.sin(theta)
        z = self.center[1] - self.radius * np.cos(theta)
        return _stack(x, z, np.full_like(t, self.rotation), scalar)

    def velocity(self, t):
        t, scalar = _times(t)
        theta, theta_rate, _ = self.phase(t)
        x = self.radius * np.cos(theta) * theta_rate
        z = self.radius * np.sin(theta) * theta_rate
        return _stack(x, z, np.zeros_like(t), scalar)

    def acceleration(self, t):
        t, scalar = _times(t)
        theta, theta_rate, theta_acc = self.phase(t)
        sin, cos = np.sin(theta), np.cos(theta)
        x = self.radius * (cos * theta_acc - sin * theta_rate**2)
        z = self.radius * (sin * theta_acc + cos * theta_rate**2)
        return _stack(x, z, np.zeros_like(t), scalar)


@dataclass(frozen=True)
class HoldTrajectory(Trajectory):
    """A constant pose.

    Parameters
    ----------
    held_pose : tuple of 3 float [m, m, rad]
        The held pose ``(x, z, phi)``; the key ``pose`` in dicts. (Not a field named
        ``pose``, which would hide the method; pass it positionally:
        ``HoldTrajectory((0, -2, 0))``.)
    """

    held_pose: tuple = (0.0, -2.0, 0.0)
    kind = "hold"

    def __post_init__(self):
        object.__setattr__(self, "held_pose", _finite_tuple("trajectory.pose", self.held_pose, 3))

    def pose(self, t):
        t, _ = _times(t)
        return np.broadcast_to(np.asarray(self.held_pose), t.shape + (3,)).copy()

    def velocity(self, t):
        t, _ = _times(t)
        return np.zeros(t.shape + (3,))

    def acceleration(self, t):
        return self.velocity(t)

    def to_dict(self):
        return {"kind": self.kind, "pose": list(self.held_pose)}


class PointToPointMotion:
    """The rest-to-rest quintic motion from ``start`` to ``end`` over ``duration`` from ``start_time``.

    Shared by the planar and the spatial point-to-point trajectories (any pose size):
    ``pose(t) = start + (end - start) s((t - start_time) / duration)``, holding outside the motion.
    """

    def turning_times(self, end_time: float) -> np.ndarray:
        """The start and the end of the motion [s] (the pose is monotone in between)."""
        return np.array([self.start_time, self.start_time + self.duration])

    def _blend(self, t):
        t = np.asarray(t, dtype=float)
        tau = (t - self.start_time) / self.duration
        inside = (tau > 0.0) & (tau < 1.0)
        value, first, second = _quintic(tau)
        # derivatives vanish outside the motion (they are also 0 at the clamped ends)
        return value, np.where(inside, first, 0.0) / self.duration, np.where(inside, second, 0.0) / self.duration**2

    def pose(self, t):
        value, _, _ = self._blend(t)
        start, end = np.asarray(self.start), np.asarray(self.end)
        return start + value[..., None] * (end - start)

    def velocity(self, t):
        _, first, _ = self._blend(t)
        return first[..., None] * (np.asarray(self.end) - np.asarray(self.start))

    def acceleration(self, t):
        _, _, second = self._blend(t)
        return second[..., None] * (np.asarray(self.end) - np.asarray(self.start))


@dataclass(frozen=True)
class PointToPointTrajectory(PointToPointMotion, Trajectory):
    """Rest-to-rest quintic motion from ``start`` to ``end``; holds outside the motion.

    ``pose(t) = start + (end - start) s((t - start_time) / duration)``, with
    ``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5``: zero velocity and acceleration at both ends.

    Parameters
    ----------
    start, end : tuple of 3 float [m, m, rad]
        Initial and final pose.
    duration : float [s]
        Motion time (> 0).
    start_time : float [s]
        Time at which the motion begins (default 0).
    """

    start: tuple = (0.0, -2.0, 0.0)
    end: tuple = (0.0, -1.6, 0.0)
    duration: float = 1.0
    start_time: float = 0.0
    kind = "point_to_point"

    def __post_init__(self):
        object.__setattr__(self, "start", _finite_tuple("trajectory.start", self.start, 3))
        object.__setattr__(self, "end", _finite_tuple("trajectory.end", self.end, 3))
        duration = _finite_float("trajectory.duration", self.duration)
        if duration <= 0.0:
            raise SceneError(f"trajectory.duration must be > 0 [s], got {shown(self.duration)}")
        object.__setattr__(self, "duration", duration)
        object.__setattr__(self, "start_time", _finite_float("trajectory.start_time", self.start_time))


#: Fields a trajectory table must give, by kind (no default would be what the user meant).
REQUIRED_FIELDS = {"point_to_point": ("end",), "hold": ("pose",)}

_KINDS = {
    "circle": CircleTrajectory,
    "hold": HoldTrajectory,
    "point_to_point": PointToPointTrajectory,
}


def trajectory_from_dict(data):
    """Build a trajectory from a dict with a ``kind`` key, as written by ``to_dict``.

    Parameters
    ----------
    data : mapping
        ``{"kind": "circle" | "hold" | "point_to_point", <fields>}``; missing fields
        take their defaults. ``hold`` takes its pose under the key ``pose``.

    Returns
    -------
    Trajectory

    Raises
    ------
    SceneError
        If ``kind`` is missing or unknown, a key is not a field of that kind, or a
        value is invalid.
    """
    if not hasattr(data, "keys"):
        raise SceneError(f"trajectory must be a table (dict), got {shown(data)}")
    values = dict(data)
    kind = values.pop("kind", None)
    if not isinstance(kind, str) or kind not in _KINDS:
        raise SceneError(f"trajectory.kind must be one of {sorted(_KINDS)}, got {shown(kind)}")
    cls = _KINDS[kind]
    missing = [name for name in REQUIRED_FIELDS.get(kind, ()) if name not in values]
    if cls is HoldTrajectory and "pose" in values:
        values["held_pose"] = values.pop("pose")
    allowed = {field.name for field in dataclass_fields(cls)}
    unknown = sorted(set(values) - allowed)
    if unknown:
        names = ["pose" if name == "held_pose" else name for name in sorted(allowed)]
        raise SceneError(f"trajectory of kind {shown(kind)} has unknown key(s) {unknown}; allowed: {names}")
    trajectory = cls(**values)  # the values given are checked first
    if missing:
        raise SceneError(f"trajectory.{missing[0]} is required for kind {shown(kind)} (a pose x [m], z [m], "
                         f"rotation [rad]); it has no sensible default")
    return trajectory
