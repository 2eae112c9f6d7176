"""Reference trajectories of the platform pose: one set of kinds for the plane and for space.

A trajectory is a pose of its :class:`~cdpr_exu.space.Space` (its ``space``, the plane unless
given) as a function of time [s]: ``(x, z, phi)`` [m, m, rad] in the paper's vertical plane,
``(x, y, z, theta_x, theta_y, theta_z)`` [m, rad] in space, with ``theta`` the platform's
rotation vector, ``R = exp([theta]x)`` (z up in both). Pure NumPy. Every trajectory offers
``pose(t)``, ``velocity(t)`` and ``acceleration(t)``: a scalar time gives shape
(pose_size,), a time array of shape ``S`` gives ``S + (pose_size,)``.

Velocity convention (the one place it is stated)
------------------------------------------------
``velocity(t)`` is the time derivative of the pose and ``acceleration(t)`` its second
derivative, entry by entry. In the plane the rotation's rate ``phi'`` is the angular
velocity. In space it is the rate of the rotation *vector*, ``theta'``, NOT the angular
velocity, which is ``omega = J_l(theta) theta'`` in the fixed frame
(:func:`cdpr_exu.core.geometry.left_jacobian`; :meth:`Trajectory.angular_velocity`,
:meth:`cdpr_exu.space.Space.angular_velocity`); the two agree only while ``theta`` and
``theta'`` are parallel (a turn about one fixed axis) or ``theta`` is 0. Likewise
``acceleration`` is not the angular acceleration.

Kinds
-----
:data:`TRAJECTORY_KINDS` holds the kinds by name (``kind = "..."`` in a scene's
``[trajectory]``): ``"hold"``, ``"point_to_point"``, ``"circle"``, ``"waypoints"`` (poses at
times in the scene) and ``"file"`` (the same from a CSV file), each written once for both spaces. A trajectory is a frozen dataclass whose fields are checked against its space
when it is made, and it round-trips through a plain dict (``to_dict`` /
:func:`trajectory_from_dict`) for TOML. Adding a kind is one subclass of :class:`Trajectory`
plus one entry ``TRAJECTORY_KINDS["name"] = Class``.

The paper's reference (scenario 1) is ``CircleTrajectory((0.0, -1.6))``:
``r_ref(t) = (0.4 sin 1.5t, -1.6 - 0.4 cos 1.5t)`` [m], orientation 0.
"""

from __future__ import annotations

import csv
from abc import ABC, abstractmethod
from dataclasses import KW_ONLY, dataclass, field, fields
from pathlib import Path
from typing import Any, ClassVar, Mapping

import numpy as np
from scipy.interpolate import BSpline, PPoly, make_interp_spline

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import entries, finite, shown
from cdpr_exu.space import PLANE, Space

__all__ = [
    "Trajectory",
    "CircleTrajectory",
    "HoldTrajectory",
    "PointToPointTrajectory",
    "WaypointsTrajectory",
    "FileTrajectory",
    "TRAJECTORY_KINDS",
    "trajectory_from_dict",
]


def _set(trajectory, name: str, value) -> None:
    object.__setattr__(trajectory, name, value)


def _pose(name: str, value, space: Space) -> tuple[float, ...]:
    """A pose of ``space`` as a tuple of floats, or SceneError naming ``name``."""
    return entries(name, value, space.pose_size, ", ".join(space.pose_units))


def _at_least(name: str, value, low: float, unit: str, strict: bool = False) -> float:
    """``value`` as a finite float >= ``low`` (> when ``strict``), or SceneError naming ``name``."""
    number = finite(name, value)
    if number < low or (strict and number == low):
        raise SceneError(f"{name} must be {'>' if strict else '>='} {low:g} [{unit}], got {shown(value)}")
    return number


def _times(t):
    """Time(s) as a float array, and whether the input was a scalar."""
    array = np.asarray(t, dtype=float)
    return array, array.ndim == 0


def _stack(components, scalar):
    """Pose entries (broadcast together) as the last axis: shape t.shape + (n,), or (n,)."""
    out = np.stack(np.broadcast_arrays(*components), axis=-1)
    return out if not scalar else out.reshape(len(components))


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
# the protocol
# ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class Trajectory(ABC):
    """A reference pose of ``space`` as a function of time [s] (see the module notes).

    Class attributes
    ----------------
    kind : str
        The name of the kind in scene files and in :data:`TRAJECTORY_KINDS`.
    required_fields : dict of str to str
        The keys a ``[trajectory]`` table of this kind must give (no default would be the
        motion its author meant), each with what it is: ``"position"`` or ``"pose"`` (of
        the space), for the message that names a missing one.
    keys : dict of str to str
        The fields whose key in a table is not their name (``held_pose`` is ``pose``).

    Parameters
    ----------
    space : Space, keyword only
        The space of the poses (:data:`~cdpr_exu.space.PLANE`, the default, or
        :data:`~cdpr_exu.space.SPACE`); the fields' sizes are checked against it.
    """

    kind: ClassVar[str] = ""
    required_fields: ClassVar[dict[str, str]] = {}
    keys: ClassVar[dict[str, str]] = {}

    space: Space = field(default=PLANE, kw_only=True)

    def __post_init__(self):
        if not isinstance(self.space, Space):
            raise SceneError(f"trajectory.space must be a Space (PLANE or SPACE), got {shown(self.space)}")

    @abstractmethod
    def pose(self, t):
        """Pose [m, rad]: shape (pose_size,) for scalar t, S + (pose_size,) for t of shape S."""

    @abstractmethod
    def velocity(self, t):
        """The pose's time derivative [m/s, rad/s] (in space the rotation vector's rate; see the module
        notes), shaped as :meth:`pose`."""

    @abstractmethod
    def acceleration(self, t):
        """The pose's second time derivative [m/s^2, rad/s^2], shaped as :meth:`pose`."""

    def angular_velocity(self, t):
        """The platform's angular velocity in the fixed frame [rad/s]: shape (rotation_size,) for scalar t,
        S + (rotation_size,) for t of shape S (``J_l(theta) theta'`` in space, ``phi'`` in the plane)."""
        start = self.space.position_size
        return self.space.angular_velocity(self.pose(t)[..., start:], self.velocity(t)[..., start:])

    def turning_times(self, end_time: float) -> np.ndarray:
        """Times in [0, end_time] [s] where a pose coordinate may be extreme (for exact workspace checks).

        The default is none: a uniform sampling of the run is used alone.
        """
        return np.zeros(0)

    @classmethod
    def table_keys(cls) -> dict[str, str]:
        """The key of each field in a ``[trajectory]`` table, by field name (all but ``space``)."""
        return {f.name: cls.keys.get(f.name, f.name) for f in fields(cls) if f.name != "space"}

    def to_dict(self) -> dict[str, Any]:
        """Plain dict with a ``kind`` key and the fields (tuples as lists), for TOML."""
        data: dict[str, Any] = {"kind": self.kind}
        for name, key in self.table_keys().items():
            value = getattr(self, name)
            data[key] = list(value) if isinstance(value, tuple) else value
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], space: Space, folder: Path | None = None) -> "Trajectory":
        """The trajectory of a ``[trajectory]`` table without its ``kind``, in ``space`` (``folder``: where a
        kind reads the files the table names, the scene file's folder).

        Raises
        ------
        SceneError
            For a key that is not a field of the kind, a required key left out, or a bad value.
        """
        keys = cls.table_keys()
        allowed = sorted(keys.values())
        unknown = sorted(set(data) - set(allowed))
        if unknown:
            raise SceneError(f"trajectory of kind {shown(cls.kind)} has unknown key(s) {unknown}; allowed: {allowed}")
        missing = [key for key in cls.required_fields if key not in data]
        if missing:
            raise SceneError(f"trajectory.{missing[0]} is required for kind {shown(cls.kind)} "
                             f"({_described(cls.required_fields[missing[0]], space)}); it has no sensible default")
        return cls(**{name: data[key] for name, key in keys.items() if key in data}, space=space)


def _described(what: str, space: Space) -> str:
    """``"position"`` or ``"pose"`` of ``space`` in words, with units (``"a pose x [m], z [m], rotation [rad]"``)."""
    if what == "position":
        return "a position " + ", ".join(f"{label} [m]" for label in space.position_labels)
    if what == "pose":
        return "a pose " + ", ".join(f"{label} [{unit}]" for label, unit in zip(space.pose_labels, space.pose_units))
    return what


# ----------------------------------------------------------------------------------
# the kinds
# ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class HoldTrajectory(Trajectory):
    """A constant pose.

    Parameters
    ----------
    held_pose : tuple of pose_size float [m, rad]
        The held pose; required; the key ``pose`` in dicts. (Not a field named ``pose``,
        which would hide the method; pass it positionally: ``HoldTrajectory((0, -2, 0))``,
        ``HoldTrajectory((0, 0, 1, 0, 0, 0), space=SPACE)``.)
    """

    kind: ClassVar[str] = "hold"
    required_fields: ClassVar[dict[str, str]] = {"pose": "pose"}
    keys: ClassVar[dict[str, str]] = {"held_pose": "pose"}

    held_pose: tuple

    def __post_init__(self):
        super().__post_init__()
        _set(self, "held_pose", _pose("trajectory.pose", self.held_pose, self.space))

    def pose(self, t):
        t, _ = _times(t)
        return np.broadcast_to(np.asarray(self.held_pose), t.shape + (len(self.held_pose),)).copy()

    def velocity(self, t):
        t, _ = _times(t)
        return np.zeros(t.shape + (len(self.held_pose),))

    def acceleration(self, t):
        return self.velocity(t)


@dataclass(frozen=True)
class PointToPointTrajectory(Trajectory):
    """Rest-to-rest quintic motion from ``start`` to ``end``; holds outside the motion.

    ``pose(t) = start + (end - start) s((t - start_time) / duration)``, with
    ``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5``: zero velocity and acceleration at both ends.
    In space the rotation vector is blended linearly, so the platform turns about one fixed
    axis only if ``start``'s and ``end``'s rotation vectors are parallel (or one is 0).

    Parameters
    ----------
    start, end : tuple of pose_size float [m, rad]
        Initial and final pose; both required.
    duration : float [s]
        Motion time (> 0, default 1).
    start_time : float [s]
        Time at which the motion begins (default 0).
    """

    kind: ClassVar[str] = "point_to_point"
    required_fields: ClassVar[dict[str, str]] = {"start": "pose", "end": "pose"}

    start: tuple
    end: tuple
    _: KW_ONLY
    duration: float = 1.0
    start_time: float = 0.0

    def __post_init__(self):
        super().__post_init__()
        _set(self, "start", _pose("trajectory.start", self.start, self.space))
        _set(self, "end", _pose("trajectory.end", self.end, self.space))
        _set(self, "duration", _at_least("trajectory.duration", self.duration, 0.0, "s", strict=True))
        _set(self, "start_time", finite("trajectory.start_time", self.start_time))

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


#: Most quarter turns of a circle a reference check samples (25 000 turns): beyond, the
#: reference turns faster than any robot could follow, and the samples would not fit in memory.
MAX_QUARTER_TURNS = 100_000


@dataclass(frozen=True)
class CircleTrajectory(Trajectory):
    """A circle in the plane of the space's first two position axes, with an optional rocking.

    ``a = c_a + R sin(p)``, ``b = c_b - R cos(p)``, the other position entries (space's z)
    held at the centre's, and the rotation ``rotation + tilt sin(p)``, for the first two
    position axes ``(a, b)``: ``(x, z)`` in the plane, a vertical circle (the paper's),
    ``(x, y)`` in space, a horizontal one. The platform starts at ``(c_a, c_b - R)`` (the
    bottom of the planar circle) and moves counter-clockwise (seen with x to the right and
    the second axis up) for ``angular_rate > 0``, rocking once per turn.

    Parameters
    ----------
    center : tuple of position_size float [m]
        Circle centre; required (no position suits every robot).
    radius : float [m]
        Circle radius ``R >= 0`` (default 0.4, the paper's).
    angular_rate : float [rad/s]
        Steady phase rate ``w`` (default 1.5, the paper's; negative: clockwise). Smaller is
        more quasi-static.
    rotation : float or tuple of 3 float [rad]
        Constant base orientation: the angle in the plane, a rotation vector in space
        (default none).
    tilt : float or tuple of 3 float [rad]
        Amplitude of the periodic rocking added to the rotation as ``tilt sin(p)``; keep it
        small (default 0: no rocking; it is written to files only when it rocks).
    ramp_time : float [s]
        0 (default, the paper): ``p = w t``, which starts at full speed. If > 0, the phase
        rate rises from rest to ``w`` along the quintic ``w s(t / T)``, so that pose,
        velocity and acceleration are continuous and the start is from rest; after the
        ramp ``p = w (t - T / 2)``. Before t = 0 the pose holds the start.
    """

    kind: ClassVar[str] = "circle"
    required_fields: ClassVar[dict[str, str]] = {"center": "position"}

    center: tuple
    _: KW_ONLY
    radius: float = 0.4
    angular_rate: float = 1.5
    rotation: Any = None
    tilt: Any = None
    ramp_time: float = 0.0

    def __post_init__(self):
        super().__post_init__()
        _set(self, "center", entries("trajectory.center", self.center, self.space.position_size, "m"))
        _set(self, "radius", _at_least("trajectory.radius", self.radius, 0.0, "m"))
        _set(self, "angular_rate", finite("trajectory.angular_rate", self.angular_rate))
        _set(self, "rotation", self.space.rotation("trajectory.rotation", self.rotation))
        _set(self, "tilt", self.space.rotation("trajectory.tilt", self.tilt))
        _set(self, "ramp_time", _at_least("trajectory.ramp_time", self.ramp_time, 0.0, "s"))

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        if not np.any(self.tilt):
            del data["tilt"]  # a circle that does not rock is written as before tilts (the planar files)
        return data

    def phase(self, t):
        """Phase ``p`` [rad] and its first two time derivatives, each of t's shape.

        With ``ramp_time`` > 0 the rate rises from 0 along the quintic blend (C2 from rest).
        """
        t = np.asarray(t, dtype=float)
        rate, ramp = self.angular_rate, self.ramp_time
        if ramp == 0.0:
            return rate * t, np.full_like(t, rate), np.zeros_like(t)
        tau = t / ramp
        blend, blend_rate, _ = _quintic(tau)
        return rate * ramp * _quintic_integral(np.maximum(tau, 0.0)), rate * blend, rate * blend_rate / ramp

    def _rocking(self):
        """(base, amplitude) [rad] of each rotation entry."""
        return zip(np.atleast_1d(self.rotation).tolist(), np.atleast_1d(self.tilt).tolist())

    def turning_times(self, end_time: float) -> np.ndarray:
        """Times [s] where a circled position entry or a rocking rotation entry is extreme: the phase
        at a multiple of pi/2, up to ``end_time``; none for a ramped circle (no closed form) or one
        that stands or neither moves nor rocks.

        Raises
        ------
        SceneError
            Naming trajectory.angular_rate when the circle makes more than :data:`MAX_QUARTER_TURNS`
            quarter turns before ``end_time``.
        """
        moves = self.radius != 0.0 or bool(np.any(self.tilt))
        if self.ramp_time > 0.0 or self.angular_rate == 0.0 or not moves:
            return np.zeros(0)
        quarter = 0.5 * np.pi / abs(self.angular_rate)
        if end_time / quarter > MAX_QUARTER_TURNS:
            raise SceneError(f"trajectory.angular_rate = {shown(self.angular_rate)} rad/s makes "
                             f"{end_time / quarter:.3g} quarter turns in {shown(end_time)} s, more than the "
                             f"{MAX_QUARTER_TURNS} a reference check samples (a circle far faster than any robot)")
        return np.arange(0.0, end_time + 1e-12, quarter)

    def pose(self, t):
        t, scalar = _times(t)
        p, _, _ = self.phase(t)
        sin, cos = np.sin(p), np.cos(p)
        position = (self.center[0] + self.radius * sin, self.center[1] - self.radius * cos,
                    *(np.full_like(t, c) for c in self.center[2:]))
        turn = tuple(np.full_like(t, base) if amplitude == 0.0 else base + amplitude * sin
                     for base, amplitude in self._rocking())
        return _stack(position + turn, scalar)

    def velocity(self, t):
        t, scalar = _times(t)
        p, p_rate, _ = self.phase(t)
        sin, cos = np.sin(p), np.cos(p)
        position = (self.radius * cos * p_rate, self.radius * sin * p_rate, *(np.zeros_like(t) for _ in self.center[2:]))
        turn = tuple(np.zeros_like(t) if amplitude == 0.0 else amplitude * cos * p_rate for _, amplitude in self._rocking())
        return _stack(position + turn, scalar)

    def acceleration(self, t):
        t, scalar = _times(t)
        p, p_rate, p_acc = self.phase(t)
        sin, cos = np.sin(p), np.cos(p)
        along, across = cos * p_acc - sin * p_rate**2, sin * p_acc + cos * p_rate**2
        position = (self.radius * along, self.radius * across, *(np.zeros_like(t) for _ in self.center[2:]))
        turn = tuple(np.zeros_like(t) if amplitude == 0.0 else amplitude * along for _, amplitude in self._rocking())
        return _stack(position + turn, scalar)


def _listed(name: str, value, what: str) -> list:
    """``value`` as a list, or SceneError naming ``name`` (a table or text is no list of ``what``)."""
    if isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__len__"):
        raise SceneError(f"{name} must be a list of {what}, got {shown(value)}")
    return list(value)


@dataclass(frozen=True)
class WaypointsTrajectory(Trajectory):
    """Poses at given times, joined by a quintic spline from rest to rest; holds outside ``times``.

    The interpolant is the quintic B-spline through every waypoint with zero velocity and zero
    acceleration at the first and the last (``scipy.interpolate.make_interp_spline``, k = 5).
    Chosen over a clamped cubic spline because its acceleration is continuous also where the
    motion leaves and reaches rest: a clamped cubic starts with zero velocity but a step in
    acceleration, which the workspace check's ``M a_ref`` and a feed-forward controller would see.
    Inside, pose to 4th derivative are continuous. The platform passes the inner waypoints
    without stopping; between sparse waypoints a spline rounds corners and may overshoot, so give
    them densely where the path must be straight (the workspace check samples every waypoint and
    each pose entry's extremes exactly: :meth:`turning_times`). In space the rotation vector is
    interpolated entry by entry, as ``point_to_point`` blends it.

    Parameters
    ----------
    times : sequence of N float [s]
        Strictly increasing, N >= 2; required.
    poses : sequence of N poses of pose_size float [m, rad]
        The pose at each time; required.
    """

    kind: ClassVar[str] = "waypoints"
    required_fields: ClassVar[dict[str, str]] = {"times": "a list of at least 2 strictly increasing times [s]",
                                                  "poses": "one pose per time"}

    times: tuple
    poses: tuple

    def __post_init__(self):
        super().__post_init__()
        times = _listed("trajectory.times", self.times, "at least 2 strictly increasing times [s]")
        if len(times) < 2:
            raise SceneError(f"trajectory.times must give at least 2 times [s], got {shown(self.times)}")
        times = entries("trajectory.times", times, len(times), "s")
        later = np.flatnonzero(np.diff(times) <= 0.0)
        if later.size:
            k = int(later[0]) + 1
            raise SceneError(f"trajectory.times must increase strictly: times[{k}] = {times[k]:g} s follows "
                             f"times[{k - 1}] = {times[k - 1]:g} s")
        poses = _listed("trajectory.poses", self.poses, "poses, one per time")
        if len(poses) != len(times):
            raise SceneError(f"trajectory.poses must give one pose per time ({len(times)}), got {len(poses)}")
        _set(self, "times", times)
        _set(self, "poses", tuple(_pose(f"trajectory.poses[{k}]", pose, self.space) for k, pose in enumerate(poses)))
        rest = [(1, np.zeros(self.space.pose_size)), (2, np.zeros(self.space.pose_size))]
        _set(self, "_spline", make_interp_spline(times, np.array(self.poses), k=5, bc_type=(rest, rest)))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "waypoints", "times": list(self.times), "poses": [list(pose) for pose in self.poses]}

    def _at(self, t, order: int):
        return self._spline(np.clip(np.asarray(t, dtype=float), self.times[0], self.times[-1]), order)

    def pose(self, t):
        return self._at(t, 0)

    def velocity(self, t):
        return self._at(t, 1)

    def acceleration(self, t):
        return self._at(t, 2)

    def turning_times(self, end_time: float) -> np.ndarray:
        """The waypoints' times and the times between them where a pose entry is extreme [s] (its rate's roots)."""
        knots, coefficients, degree = self._spline.tck
        roots = [PPoly.from_spline(BSpline(knots, column, degree).derivative()).roots(extrapolate=False)
                 for column in coefficients.T]
        times = np.concatenate([self.times, *roots])
        return times[np.isfinite(times)]  # a pose entry that stands still has no roots, but NaN


class FileTrajectory(WaypointsTrajectory):
    """``kind = "file"``: the waypoints of :class:`WaypointsTrajectory` read from a CSV file.

    The table's one key, ``path``, names the file, relative to the scene file's folder. Its
    header names the columns, each with its unit in the name as a run's ``pose.csv`` has them
    (``time_s``, then the Space's ``pose_columns``): ``time_s, x_m, z_m, rotation_rad`` in the
    plane, ``time_s, x_m, y_m, z_m, rotation_x_rad, rotation_y_rad, rotation_z_rad`` in space (the
    rotation vector); other columns are ignored (a run's ``pose.csv`` reads back as its platform's
    path). One row per waypoint. The file is read once, when the scene is loaded, into a
    :class:`WaypointsTrajectory`: a scene saved then (a run folder's ``scene.toml``) holds the
    waypoints themselves and reruns without the file.
    """

    kind: ClassVar[str] = "file"

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], space: Space, folder: Path | None = None) -> WaypointsTrajectory:
        """The waypoints of the file ``data["path"]``; SceneError naming the file, the line and the column."""
        columns = ("time_s",) + space.pose_columns
        if set(data) != {"path"} or not isinstance(data["path"], str):
            raise SceneError(f"trajectory of kind 'file' takes one key, path (a CSV file of {', '.join(columns)}, "
                             f"relative to the scene file), got {shown(dict(data))}")
        path, where = Path(folder or ".") / data["path"], f"trajectory.path {shown(data['path'])}"
        try:
            lines = list(csv.reader(path.read_text(encoding="utf-8").splitlines()))
        except (OSError, UnicodeDecodeError) as err:
            raise SceneError(f"{where}: cannot read {path}: {getattr(err, 'strerror', None) or err}") from None
        header = [name.strip() for name in lines[0]] if lines else []
        missing = [name for name in columns if name not in header]
        if missing:
            raise SceneError(f"{where} lacks the column(s) {', '.join(missing)}: a {space.name} trajectory file's "
                             f"header names {', '.join(columns)} ({space.pose_size} pose columns; units s, m, rad), "
                             f"got {shown(header)}")
        index, rows = [header.index(name) for name in columns], []
        for number, line in enumerate(lines[1:], 2):
            try:
                rows += [[float(line[i]) for i in index]] if line else []
            except (ValueError, IndexError):
                raise SceneError(f"{where}, line {number}: {shown(line)} does not give a number in each of "
                                 f"{', '.join(columns)}") from None
        try:
            return WaypointsTrajectory(tuple(row[0] for row in rows), tuple(row[1:] for row in rows), space=space)
        except SceneError as err:
            raise SceneError(f"{where} (the row on line k + 2 read as times[k] and poses[k]): {err}") from None


# ----------------------------------------------------------------------------------
# the registry
# ----------------------------------------------------------------------------------
#: The trajectory kinds by name (``kind = "..."`` in a scene's ``[trajectory]``).
TRAJECTORY_KINDS: dict[str, type[Trajectory]] = {
    "circle": CircleTrajectory,
    "file": FileTrajectory,
    "hold": HoldTrajectory,
    "point_to_point": PointToPointTrajectory,
    "waypoints": WaypointsTrajectory,
}


def trajectory_from_dict(data: Any, space: Space, folder: Path | None = None) -> Trajectory:
    """Build a trajectory of ``space`` from a dict with a ``kind`` key, as written by ``to_dict``.

    Parameters
    ----------
    data : mapping
        ``{"kind": <a name in TRAJECTORY_KINDS>, <fields>}``. Required: ``center``
        (circle), ``pose`` (hold; the key is ``pose``, not the field name ``held_pose``),
        ``start`` and ``end`` (point_to_point), ``times`` and ``poses`` (waypoints), ``path``
        (file); other missing fields take their defaults.
    space : Space
        The scene's space (:data:`~cdpr_exu.space.PLANE` or :data:`~cdpr_exu.space.SPACE`).
    folder : path, optional
        Where relative file names are read from (the scene file's folder; default the working one).

    Returns
    -------
    Trajectory

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
    if not isinstance(kind, str) or kind not in TRAJECTORY_KINDS:
        raise SceneError(f"trajectory.kind must be one of {sorted(TRAJECTORY_KINDS)}, got {shown(kind)}")
    return TRAJECTORY_KINDS[kind].from_dict(values, space, folder)
