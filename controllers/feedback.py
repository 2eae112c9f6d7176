"""Position feedback around a feed-forward: a PI loop on the filtered platform pose error, planar or spatial.

:class:`FilteredPositionPI` turns the position error e = r_ref - r [m] (with ``rotation`` also
phi [rad], R(phi) = R_ref R^T) into length corrections through a second-order Butterworth
low-pass (``cutoff`` [Hz]) and the ideal inverse-kinematics Jacobian U = -A^T at the reference
pose (a length change U d moves the platform by about d):

    dlambda = w(t) U(r_ref) (k_p e_f + k_i integral(w e_f) dt),

w(t) a quintic fade-in over ``start_time``. Why the filter: unfiltered (k_p = 2), the
platform's jolts reached the winch command (1300 m/s^2 against 5 open loop), a slack winch
element snapped taut and paper-circle-mismatch diverged at 0.9 s; above a few hertz the
measured response has no usable phase. (Velocity feedback fed the start-up jolt in and
diverged too.) A call at or before an earlier one (a retried step) restarts from the state
at the last earlier time. With ``margin_check`` a loop :mod:`controllers.loop_design` models
is checked before the run against :data:`~controllers.loop_design.REQUIRED_MARGINS`.
:class:`ClosedLoopController` puts the loop around any open-loop controller. Plain NumPy.
"""

from __future__ import annotations

import warnings
from typing import Callable

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import rotation_vector
from cdpr_exu.core.validation import shown
from cdpr_exu.statics.kinematics import length_jacobian

from . import loop_design
from .base import Measurement, WinchCommand, quintic_blend

#: What a loop short of the required margins does at ``reset``: "off", not checked; "refuse", a SceneError;
#: "feed_forward", no correction in that run, and a warning.
MARGIN_CHECKS = ("off", "refuse", "feed_forward")


def _rotation_coordinates(matrix: np.ndarray) -> np.ndarray:
    """The angle (1,) of a 2 x 2 rotation matrix, the rotation vector (3,) of a 3 x 3 one [rad]."""
    if matrix.shape == (2, 2):
        return np.array([np.arctan2(matrix[1, 0], matrix[0, 0])])
    return rotation_vector(matrix)


class FilteredPositionPI:
    """PI correction of the winch lengths from the low-pass filtered platform position error.

    Parameters
    ----------
    proportional_gain, integral_gain : float [-, 1/s]
        k_p and k_i, >= 0 (defaults: :data:`controllers.loop_design.DESIGNED`, chosen from the loop's margins).
    cutoff : float [Hz]
        Of the error filter (> 0).
    start_time : float [s]
        The feedback and its integral fade in over this time (>= 0).
    rotation : bool
        Feed the rotation error back too (a rigid platform only).
    margin_check : {"off", "refuse", "feed_forward"}
        :data:`MARGIN_CHECKS`; "off" by default: the default gains keep >= 10 dB and >= 33 deg on the
        paper robot's 13 plants (docs/robustness.md), and the check costs about 1.5 s of CPU per pose
        (about 4 s on a spatial robot of 8 x 20 elements).

    Raises
    ------
    SceneError
        If an option is not finite or out of its range (naming it); at ``reset``, with
        ``margin_check = "refuse"``, for a loop short of the required margins.
    """

    def __init__(self, proportional_gain: float = loop_design.DESIGNED.proportional_gain,
                 integral_gain: float = loop_design.DESIGNED.integral_gain, cutoff: float = loop_design.DESIGNED.cutoff,
                 start_time: float = 0.5, rotation: bool = False, margin_check: str = "off"):
        for name, value in (("proportional_gain", proportional_gain), ("integral_gain", integral_gain)):
            if not np.isfinite(value) or value < 0:
                raise SceneError(f"{name} must be zero or positive, got {shown(value)}")
        if not np.isfinite(start_time) or start_time < 0:
            raise SceneError(f"start_time must be zero or positive, got {shown(start_time)}")
        if not np.isfinite(cutoff) or cutoff <= 0:
            raise SceneError(f"cutoff must be positive [Hz], got {shown(cutoff)}")
        if margin_check not in MARGIN_CHECKS:
            raise SceneError(f"margin_check must be one of {MARGIN_CHECKS}, got {shown(margin_check)}")
        self.proportional_gain = float(proportional_gain)
        self.integral_gain = float(integral_gain)
        self.cutoff = float(cutoff)
        self.start_time = float(start_time)
        self.rotation = bool(rotation)
        self.margin_check = margin_check
        self._scene = None
        #: The worst margins over the run's poses found at the last ``reset`` (None: not checked).
        self.margins = None
        #: Whether the loop is off for this run (its margins fell short with ``margin_check = "feed_forward"``).
        self.off = False

    def reset(self, scene) -> None:
        """Start a run of ``scene`` with the filter and the integral at zero, its margins checked."""
        self._scene, self.margins, self.off = scene, None, False
        if self.margin_check != "off" and loop_design.models(scene):
            gains = loop_design.LoopGains(self.proportional_gain, self.integral_gain, self.cutoff)
            self.margins = loop_design.check_loop(scene, gains, rotation=self._with_rotation(scene))
            if not loop_design.meets(self.margins):
                m = self.margins
                text = (f"the position loop (k_p {gains.proportional_gain:g}, k_i {gains.integral_gain:g} /s, f_c "
                        f"{gains.cutoff:g} Hz) keeps a gain margin of {m.gain_margin_db:.1f} dB and a phase margin of "
                        f"{m.phase_margin_deg:.1f} deg{'' if m.stable else ' (unstable)'} on scene {scene.name!r}, "
                        f"below the required {loop_design.REQUIRED_MARGINS[0]:g} dB and "
                        f"{loop_design.REQUIRED_MARGINS[1]:g} deg")
                if self.margin_check == "refuse":
                    raise SceneError(f"{text}: lower the gains, or margin_check='feed_forward' runs the feed-forward "
                                     "alone")
                warnings.warn(f"{text}: the run uses the feed-forward alone", loop_design.PoorMarginsWarning,
                              stacklevel=2)
                self.off = True
        size = self.error_size(scene)
        # (time, filtered error, its rate, integral of the filtered error), one entry per call
        self._history = [(0.0, np.zeros(size), np.zeros(size), np.zeros(size))]

    @property
    def integral(self) -> np.ndarray:
        """Integral of the filtered error at the last call [m s, rad s], shape (error_size,)."""
        return self._history[-1][3]

    def _with_rotation(self, scene) -> bool:
        return self.rotation and not scene.platform.is_point_mass

    def error_size(self, scene) -> int:
        """Length of the error the loop filters: the position's, with ``rotation`` (rigid) the rotation's."""
        space = scene.space
        return space.position_size + (space.rotation_size if self._with_rotation(scene) else 0)

    def target(self, time: float) -> np.ndarray:
        """The scene's reference pose at ``time`` [s] [m, rad]."""
        return np.asarray(self._scene.trajectory.pose(time), dtype=float)

    def error(self, goal: np.ndarray, pose: np.ndarray) -> np.ndarray:
        """The error (r_goal - r, phi), R(phi) = R_goal R^T (with ``rotation``), shape (error_size,)."""
        space = self._scene.space
        size = space.position_size
        position = goal[:size] - pose[:size]
        if not self._with_rotation(self._scene):
            return position
        turn = space.rotation_matrix(goal[size:]) @ space.rotation_matrix(pose[size:]).T
        return np.concatenate([position, _rotation_coordinates(turn)])

    def jacobian(self, pose: np.ndarray) -> np.ndarray:
        """d(lambda)/d(error) of the ideal cables at ``pose``, shape (m, error_size) [m/m, m/rad]: the first
        columns of :func:`cdpr_exu.statics.kinematics.length_jacobian`."""
        return length_jacobian(self._scene, pose)[:, :self.error_size(self._scene)]

    def _advance(self, time: float, error: np.ndarray, weight: float):
        """The filter and integral state at ``time`` [s] from the last earlier call, and stored."""
        history = self._history
        while len(history) > 1 and history[-1][0] >= time:
            history.pop()  # a retried step: start again from the last earlier state
        last, filtered, rate, integral = history[-1]
        dt = time - last
        if dt <= 0:
            return filtered, integral
        omega = 2.0 * np.pi * self.cutoff
        # Semi-implicit Euler on e_f'' = omega^2 (e - e_f) - 2 zeta omega e_f', substeps of 0.2 / omega.
        substeps = max(1, int(np.ceil(dt * omega / 0.2)))
        h = dt / substeps
        filtered, rate = filtered.copy(), rate.copy()
        for _ in range(substeps):
            rate += h * (omega**2 * (error - filtered) - 2.0 * loop_design.FILTER_DAMPING * omega * rate)
            filtered += h * rate
        integral = integral + filtered * dt * weight
        history.append((time, filtered, rate, integral))
        if len(history) > 64:  # retries reach back one step: a short history is enough
            del history[:-16]
        return filtered, integral

    def correction(self, measurement: Measurement, target: Callable[[float], np.ndarray] | None = None) -> np.ndarray:
        """Length correction dlambda at ``measurement.time``, shape (m,) [m]; SceneError without a pose.

        The error is taken at ``measurement.state_time``, when the pose was measured (one step
        earlier: against the later target it would be biased by the velocity times the step,
        1.2 mm at 0.6 m/s and 2 ms). ``target(t)``: the pose [m, rad] the loop holds the platform
        to (its position at least; default: the reference); the Jacobian is the reference pose's either way.
        """
        if self._scene is None:
            raise RuntimeError(f"{type(self).__name__}.reset(scene) must be called first")
        if measurement.platform_pose is None:
            raise SceneError("the position feedback needs the measured platform pose")
        if self.off:
            return np.zeros(self._scene.n_cables)
        measured_at = measurement.time if measurement.state_time is None else measurement.state_time
        if target is None:
            goal = self.target(measured_at)
        else:
            goal = np.asarray(target(measured_at), dtype=float)
        error = self.error(goal, np.asarray(measurement.platform_pose, dtype=float))
        reference = self._scene.trajectory.pose(measurement.time)
        # the feedback fades in: switched on at once, the winch speed jumps and the over-damped winch
        # element pushes (-62 N measured with spring cables)
        weight = float(quintic_blend(measurement.time / self.start_time)[0]) if self.start_time > 0 else 1.0
        filtered, integral = self._advance(measurement.time, error, weight)
        feedback = weight * (self.proportional_gain * filtered + self.integral_gain * integral)
        return self.jacobian(reference) @ feedback


#: What :class:`ClosedLoopController` holds the platform to: "expected", the path the feed-forward gave on
#: the controller's model, or "reference".
FOLLOW = ("expected", "reference")


class ClosedLoopController:
    """An open-loop controller (the feed-forward) plus :class:`FilteredPositionPI` feedback (:data:`FOLLOW`).

    Following the path the feed-forward ``expected_pose(t)`` gave on the model, the loop
    acts only on what the model gets wrong and leaves the feed-forward's own residual (the
    cables' fast modes, which the late loop would amplify) alone. On paper-circle-mismatch
    (lengths learned on the model: 2.87 mm there, 10.2 mm open loop on the plant): 2.26 mm,
    against 4.11 mm and 0.30 s slack following the reference.

    Raises
    ------
    SceneError
        If ``feed_forward`` reads the pose or the tensions, ``feedback`` is not a
        :class:`FilteredPositionPI` or ``follow`` not one of :data:`FOLLOW`; at ``reset``, if
        ``follow = "expected"`` and the feed-forward expects no path.
    """

    uses_pose = True
    uses_tension = False

    def __init__(self, name: str, feed_forward, feedback: FilteredPositionPI, follow: str = "expected"):
        if not callable(getattr(feed_forward, "command", None)) or not callable(getattr(feed_forward, "reset", None)):
            raise SceneError(f"feed_forward must be a controller (reset and command), got {shown(feed_forward)}")
        if getattr(feed_forward, "uses_pose", True) or getattr(feed_forward, "uses_tension", True):
            raise SceneError(f"feed_forward must be open loop (uses_pose and uses_tension False), "
                             f"got {shown(getattr(feed_forward, 'name', feed_forward))}")
        if not isinstance(feedback, FilteredPositionPI):
            raise SceneError(f"feedback must be a FilteredPositionPI, got {shown(feedback)}")
        if follow not in FOLLOW:
            raise SceneError(f"follow must be one of {FOLLOW}, got {shown(follow)}")
        self.name = name
        self.feed_forward = feed_forward
        self.feedback = feedback
        self.follow = follow

    @property
    def learner(self):
        """The feed-forward's learner, if any (``cdpr compare`` reports its trials)."""
        return getattr(self.feed_forward, "learner", None)

    def reset(self, scene, initial_paid_out) -> None:
        """Reset the feed-forward (a learned one learns here) and the feedback."""
        self.feed_forward.reset(scene, initial_paid_out)
        if self.follow == "expected":
            expected = getattr(self.feed_forward, "expected_pose", None)
            if expected is None or expected(0.0) is None:
                raise SceneError(f"follow = 'expected' needs a feed-forward that expects a path (expected_pose), "
                                 f"{shown(getattr(self.feed_forward, 'name', self.feed_forward))} does not")
        self.feedback.reset(scene)

    def command(self, measurement: Measurement) -> WinchCommand:
        feed_forward = self.feed_forward.command(measurement)
        target = self.feed_forward.expected_pose if self.follow == "expected" else None
        correction = self.feedback.correction(measurement, target)
        return WinchCommand(np.asarray(feed_forward.paid_out, dtype=float) + correction,
                            np.asarray(feed_forward.paid_out_rate, dtype=float))
