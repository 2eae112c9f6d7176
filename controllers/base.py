"""The narrow interface between the simulated robot and its controllers.

A controller never sees Exudyn: once per time step (not per Newton iteration) it receives
a :class:`Measurement` (time, winch state and, where it declares that it uses them, the
platform pose and the cable tensions) and returns a :class:`WinchCommand`. The winch
variable is the *paid-out length* lambda_i [m], the unstrained cable beyond the hang point
(:mod:`cdpr_exu.core.geometry`); hauling in decreases it. Every run wraps its controller in
:class:`SmoothStart`.
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
    paid_out, paid_out_rate : ndarray, shape (m,) [m, m/s]
        Each winch's paid-out length and rate: the last command's rate (kinematic winches;
        zero before the first command), or the drum's measured one (servo winches).
    platform_pose : ndarray, shape (3,) or (6,), or None [m, rad]
        Only for ``uses_pose``: (x, z, rotation) planar; (x, y, z, rotation vector) spatial.
    platform_velocity : ndarray, shape (3,) or (6,), or None [m/s, rad/s]
        The pose's time derivative (spatial: the rotation vector's rate,
        :meth:`cdpr_exu.space.Space.rotation_rate`).
    cable_tensions : ndarray, shape (m,) or None [N]
        At the platform end of each cable, only for ``uses_tension``.
    state_time : float or None [s]
        When the pose, velocity and tensions were measured: the start of the step being
        solved, one step before ``time``. None: ``time``.
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
    """Winch set-points for one time step: paid-out lengths (m,) [m] and their rates (m,) [m/s]."""

    paid_out: np.ndarray
    paid_out_rate: np.ndarray


@runtime_checkable
class Controller(Protocol):
    """Maps measurements to winch commands; ``name`` in reports, ``uses_pose`` and ``uses_tension`` say what
    :meth:`command` reads."""

    name: str
    uses_pose: bool
    uses_tension: bool

    def reset(self, scene, initial_paid_out) -> None:
        """Prepare for a run of ``scene``; ``initial_paid_out`` (m,) [m]: what was paid out at t = 0."""

    def command(self, measurement: Measurement) -> WinchCommand:
        """The winch command for ``measurement.time``."""


def quintic_blend(tau):
    """The rest-to-rest quintic s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, clamped to [0, 1], and s'."""
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    return tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2), 30.0 * tau**2 * (1.0 - tau) ** 2


#: Where a model-based open-loop command starts from: "absolute", the model's lengths L(t) (the run's
#: SmoothStart blends in their offset from the paid-out p0); "relative", p0 + L(t) - L(0); "calibrated",
#: that change counted from the pose p measured at the start: p0 + L(t) - L(0) - (l(p) - l(r(0))), l the
#: ideal lengths.
STARTS = ("absolute", "relative", "calibrated")


class CommandStart:
    """The ``start`` rule of a model-based open-loop command, one of :data:`STARTS` (else SceneError)."""

    def __init__(self, start: str = "absolute") -> None:
        if start not in STARTS:
            from cdpr_exu.core.errors import SceneError

            raise SceneError(f"start must be one of {STARTS}, got {shown(start)}")
        self.start = start
        self._scene = self._offset = None

    @property
    def uses_pose(self) -> bool:
        """True for "calibrated" (it reads the pose at t = 0)."""
        return self.start == "calibrated"

    def commands(self, scene, lengths: np.ndarray, initial_paid_out) -> np.ndarray:
        """The commands (N, m) [m] from the model's ``lengths`` (N, m) along the reference."""
        self._scene, self._offset = scene, None
        if self.start == "absolute":
            return lengths
        return np.asarray(initial_paid_out, dtype=float) + lengths - lengths[0]

    def offset(self, measurement: Measurement):
        """What "calibrated" takes off the commands, l(p) - l(r(0)) [m] (p measured first); 0 otherwise."""
        if self.start != "calibrated":
            return 0.0
        if self._offset is None:
            from cdpr_exu.core.errors import SceneError
            from cdpr_exu.statics.kinematics import ideal_paid_out

            if measurement.platform_pose is None:
                raise SceneError("start = 'calibrated' needs the measured pose at the start")
            # the centre moved to the reference's start, the rotation held (as the position loop's Jacobian)
            poses = np.array([measurement.platform_pose, measurement.platform_pose], dtype=float)
            size = self._scene.space.position_size
            poses[1, :size] = np.asarray(self._scene.trajectory.pose(0.0), dtype=float)[:size]
            ideal = ideal_paid_out(self._scene, poses)[0]
            self._offset = ideal[0] - ideal[1]
        return self._offset


class SmoothStart:
    """A controller whose commands start at what the winches paid out at t = 0, p0.

    The command is c(t) + (1 - s(t / T)) (p0 - c(0)), s the quintic blend over T = ``duration``
    [s]: the offset between the straight cables as built and where the controller wants them
    (e.g. with sag and stretch) is taken up with zero rate and acceleration at both ends. A
    controller that starts at p0 (ideal IK) is unchanged, so the paper's abrupt start stays.
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
        """Reset the controller and measure its command at t = 0, the platform at rest at ``initial_pose``
        [m, rad] (default ``scene.platform.initial_pose``), against ``initial_paid_out``."""
        initial = np.asarray(initial_paid_out, dtype=float)
        self.controller.reset(scene, initial.copy())
        m = initial.size
        pose = velocity = None
        if self.uses_pose:
            pose = np.asarray(scene.platform.initial_pose if initial_pose is None else initial_pose, dtype=float)
            velocity = np.zeros_like(pose)
        first = self.controller.command(Measurement(0.0, initial.copy(), np.zeros(m), pose, velocity, None))
        offset = initial - np.asarray(first.paid_out, dtype=float)
        # below 1e-12 m the offset is round-off (ideal IK's "initial + change"): its commands stay bit for bit
        self._offset = np.where(np.abs(offset) < 1e-12, 0.0, offset)

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._offset is None:
            raise RuntimeError("SmoothStart.reset(scene, initial_paid_out) must be called before command()")
        command = self.controller.command(measurement)
        if measurement.time >= self.duration or not self._offset.any():
            # the blend is over, or there is nothing to blend
            return WinchCommand(np.asarray(command.paid_out, dtype=float), np.asarray(command.paid_out_rate, dtype=float))
        blend, rate = quintic_blend(measurement.time / self.duration)
        return WinchCommand(np.asarray(command.paid_out, dtype=float) + (1.0 - blend) * self._offset,
                            np.asarray(command.paid_out_rate, dtype=float) - rate / self.duration * self._offset)
