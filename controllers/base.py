"""The narrow interface between the simulated robot and its controllers.

A controller never sees Exudyn: it receives a :class:`Measurement` (time, winch
state and, where it declares that it uses them, the platform pose and the cable
tensions) and returns a :class:`WinchCommand`. The simulation asks for a command
once per time step, not once per Newton iteration.

The winch variable is the *paid-out length* lambda_i [m]: the unstrained cable length
between the point where cable i leaves its winch-side vertical line on the pulley
(the hang point) and the platform anchor. Hauling in decreases it. The simulation
tells each controller what was paid out at t = 0 (``reset``).

Every controller starts the same way (:class:`SmoothStart`, applied by the run): its
commands begin at what the winches paid out at t = 0 and take up the controller's own
commands over :data:`START_BLEND_TIME`. A reference that starts from rest (a circle
with ``ramp_time`` > 0) then gives commands that start with zero rate and acceleration.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from cdpr_exu.core.validation import shown

#: Duration of the blend from the paid-out lengths at t = 0 into a controller's commands [s].
START_BLEND_TIME = 0.5


@dataclass(frozen=True)
class Measurement:
    """What a controller may read at one time step.

    Attributes
    ----------
    time : float [s]
        The time the command is for (the end of the step being solved).
    paid_out : ndarray, shape (m,) [m]
        Current paid-out length of each winch.
    paid_out_rate : ndarray, shape (m,) [m/s]
        The winches' rate, the same rule on planar and spatial robots: the last command's
        rate (kinematic winches; zero before the first command), or the drum's measured
        rate (planar servo winches).
    platform_pose : ndarray, shape (3,) or (6,), or None [m, rad]
        Measured pose, only for controllers with ``uses_pose``: (x, z, rotation) on a
        planar robot; (x, y, z, rotation vector) on a spatial one (the rotation vector
        of the platform's rotation matrix, zero for a point mass).
    platform_velocity : ndarray, shape (3,) or (6,), or None [m/s, rad/s]
        Its velocity, the pose's time derivative in both spaces: (vx, vz, angular rate) planar;
        (vx, vy, vz, rate of the rotation vector) spatial, which is ``J_l(theta)^-1`` times the
        angular velocity in the fixed frame (:meth:`cdpr_exu.space.Space.rotation_rate`; zero for a
        point mass), as the spatial trajectories give their rates.
    cable_tensions : ndarray, shape (m,) or None [N]
        Tension at the platform end of each cable, only for ``uses_tension``.
    state_time : float or None [s]
        The time the pose, velocity and tensions were measured at: the start of the step
        being solved (the state the solver has), one step before ``time``. None: ``time``.
    """

    time: float
    paid_out: np.ndarray
    paid_out_rate: np.ndarray
    platform_pose: np.ndarray | None = None
    platform_velocity: np.ndarray | None = None
    cable_tensions: np.ndarray | None = None
    state_time: float | None = None


@dataclass(frozen=True)
class WinchCommand:
    """Winch set-points for one time step.

    Attributes
    ----------
    paid_out : ndarray, shape (m,) [m]
        Commanded paid-out length of each winch.
    paid_out_rate : ndarray, shape (m,) [m/s]
        Its time derivative (feed-forward velocity).
    """

    paid_out: np.ndarray
    paid_out_rate: np.ndarray


@runtime_checkable
class Controller(Protocol):
    """Maps measurements to winch commands.

    Attributes
    ----------
    name : str
        Short name used in reports and tables.
    uses_pose, uses_tension : bool
        Whether :meth:`command` reads the platform pose or the cable tensions.
    """

    name: str
    uses_pose: bool
    uses_tension: bool

    def reset(self, scene, initial_paid_out) -> None:
        """Prepare for a run of ``scene`` (precompute command tables).

        ``initial_paid_out`` (shape (m,) [m]) is what the winches have paid out at t = 0.
        """

    def command(self, measurement: Measurement) -> WinchCommand:
        """The winch command for ``measurement.time``."""


def quintic_blend(tau):
    """The rest-to-rest quintic s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 and its first derivative.

    Clamped to 0 before tau = 0 and 1 after tau = 1; s' and s'' vanish at both ends.
    """
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    return tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2), 30.0 * tau**2 * (1.0 - tau) ** 2


#: Where a model-based open-loop command starts from (``start`` of the tension-aware controllers):
#: "absolute", the model's lengths L(t) themselves (:class:`SmoothStart` blends in their offset from the
#: paid-out lengths p0); "relative", p0 + L(t) - L(0), the model's change since the reference's start;
#: "calibrated", that change counted from the pose p the robot is measured at when the run starts (the
#: rest a real robot starts from): p0 + L(t) - L(0) - (l(p) - l(r(0))), l the ideal lengths, r the reference
#: position with the measured rotation.
STARTS = ("absolute", "relative", "calibrated")


class CommandStart:
    """The ``start`` rule of a model-based open-loop command (:data:`STARTS`).

    Parameters
    ----------
    start : {"absolute", "relative", "calibrated"}

    Raises
    ------
    SceneError
        If ``start`` is not one of :data:`STARTS`.
    """

    def __init__(self, start: str = "absolute") -> None:
        if start not in STARTS:
            from cdpr_exu.core.errors import SceneError

            raise SceneError(f"start must be one of {STARTS}, got {shown(start)}")
        self.start = start
        self._scene = self._offset = None

    @property
    def uses_pose(self) -> bool:
        """True for "calibrated": it reads the measured pose once, at t = 0."""
        return self.start == "calibrated"

    def commands(self, scene, lengths: np.ndarray, initial_paid_out) -> np.ndarray:
        """The tabulated commands, shape (N, m) [m], from the model's ``lengths`` (N, m) along the reference."""
        self._scene, self._offset = scene, None
        if self.start == "absolute":
            return lengths
        return np.asarray(initial_paid_out, dtype=float) + lengths - lengths[0]

    def offset(self, measurement: Measurement):
        """What "calibrated" takes off the commands, l(p) - l(r(0)) [m], p the pose of the first measurement
        (kept); 0 for the other rules."""
        if self.start != "calibrated":
            return 0.0
        if self._offset is None:
            from cdpr_exu.core.errors import SceneError
            from cdpr_exu.statics.kinematics import ideal_paid_out

            if measurement.platform_pose is None:
                raise SceneError("start = 'calibrated' needs the measured pose at the start")
            # the centre moved from where it was measured to the reference's start, the rotation held (a
            # two-cable planar robot does not command it), as the position loop's Jacobian does
            poses = np.array([measurement.platform_pose, measurement.platform_pose], dtype=float)
            size = self._scene.space.position_size
            poses[1, :size] = np.asarray(self._scene.trajectory.pose(0.0), dtype=float)[:size]
            ideal = ideal_paid_out(self._scene, poses)[0]
            self._offset = ideal[0] - ideal[1]
        return self._offset


class SmoothStart:
    """A controller whose commands start at what the winches paid out at t = 0.

    The run wraps every controller in it. With c(t) the controller's command and p0 the
    paid-out lengths at t = 0, the command is

        c(t) + (1 - s(t / T)) (p0 - c(0)),

    s the quintic blend over T = ``duration``: the offset between where the cables start
    (straight, as built) and where the controller wants them at t = 0 (e.g. the
    tension-aware lengths, with sag and stretch) is taken up with zero rate and
    acceleration at both ends. A controller whose command starts at p0 (ideal inverse
    kinematics) is unchanged, so the paper's abrupt start stays the paper's. The rate
    and acceleration of the command at t = 0 are those of c: zero for a reference that
    starts from rest.

    Parameters
    ----------
    controller : Controller
    duration : float [s]
        The blend time T (> 0).
    """

    def __init__(self, controller: Controller, duration: float = START_BLEND_TIME) -> None:
        if not np.isfinite(duration) or duration <= 0:
            raise ValueError(f"duration must be positive [s], got {shown(duration)}")
        self.controller = controller
        self.duration = float(duration)
        self.name = controller.name
        self.uses_pose = controller.uses_pose
        self.uses_tension = controller.uses_tension
        self._offset = None

    def reset(self, scene, initial_paid_out, initial_pose=None) -> None:
        """Reset the controller and measure its command at t = 0 against ``initial_paid_out``.

        The command at t = 0 is asked with the platform at rest at ``initial_pose`` (shape (3,)
        planar or (6,) spatial [m, rad]; by default ``scene.platform.initial_pose``).
        """
        initial = np.asarray(initial_paid_out, dtype=float)
        self.controller.reset(scene, initial.copy())
        m = initial.size
        pose = velocity = None
        if self.uses_pose:
            pose = np.asarray(scene.platform.initial_pose if initial_pose is None else initial_pose, dtype=float)
            velocity = np.zeros_like(pose)
        first = self.controller.command(Measurement(0.0, initial.copy(), np.zeros(m), pose, velocity, None))
        offset = initial - np.asarray(first.paid_out, dtype=float)
        # Below 1e-12 m the offset is the round-off of a controller's own "initial + change"
        # (ideal IK): dropped, so that a controller that starts where the winches are keeps
        # its commands bit for bit.
        self._offset = np.where(np.abs(offset) < 1e-12, 0.0, offset)

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._offset is None:
            raise RuntimeError("SmoothStart.reset(scene, initial_paid_out) must be called before command()")
        command = self.controller.command(measurement)
        if measurement.time >= self.duration or not self._offset.any():
            # the blend is over (s = 1, s' = 0) or there is nothing to blend: c(t) itself
            return WinchCommand(np.asarray(command.paid_out, dtype=float), np.asarray(command.paid_out_rate, dtype=float))
        blend, rate = quintic_blend(measurement.time / self.duration)
        return WinchCommand(np.asarray(command.paid_out, dtype=float) + (1.0 - blend) * self._offset,
                            np.asarray(command.paid_out_rate, dtype=float) - rate / self.duration * self._offset)
