"""Position feedback around a feed-forward: a PI loop on the filtered platform pose error, planar or spatial.

:class:`FilteredPositionPI` turns the measured platform position error e = r_ref - r
((x, z) or (x, y, z) [m]; with ``rotation`` also phi [rad], the rotation that takes the measured
orientation to the reference one, R(phi) = R_ref R^T) into winch length corrections: the error passes a second-order low-pass
filter (Butterworth, cut-off ``cutoff`` [Hz]) and is mapped onto the cables with the
ideal inverse-kinematics Jacobian U = -A^T at the reference pose (A the structure matrix,
:func:`cdpr_exu.statics.kinematics.structure_matrix`; rows: unit vectors from each cable's exit
to its anchor, and their moments), so that a length change U d moves the platform by about d:

    dlambda = w(t) U(r_ref) (k_p e_f + k_i integral(w e_f) dt),

e_f the filtered error and w(t) a quintic fade-in from 0 at t = 0 to 1 at ``start_time``.

Before a run (``margin_check``), a loop whose robot :mod:`controllers.loop_design` models (planar, two
cables, the position fed back) has its gain and phase margins computed on the controllers' model
(:func:`~controllers.loop_design.check_loop`, about 6 s); below :data:`~controllers.loop_design.REQUIRED_MARGINS`
(6 dB, 30 deg) it refuses the run, naming the gains and the margins, or runs without its correction (the
feed-forward alone) and warns (:class:`~controllers.loop_design.PoorMarginsWarning`).

Why the filter: with tension-only cables, an unfiltered loop (k_p = 2) passed the
platform's jolts straight into the winch command (command accelerations up to
1300 m/s^2 measured, against 5 m/s^2 open loop); a winch element that then went slack
snapped taut and the run diverged (0.9 s into paper-circle-mismatch). The filter keeps
the command smooth above a few hertz, where the measured position response has no
usable phase. (Velocity feedback was tried and dropped: it feeds the start-up jolt into
the winch command and the run diverges.)

The filter and the integral are integrated from one call to the next; a call at or
before an earlier one (the solver retrying a step with a smaller size) restarts from the
state at the last earlier time, so a retried step is not counted twice.

:class:`ClosedLoopController` puts the loop around any open-loop controller (its
feed-forward), such as lengths learned on the controller's model (:mod:`controllers.ilc`),
which already hold the cables' dynamics as the model has them. It can hold the platform
to the path those lengths gave on the model rather than to the reference, so that the
feedback is left with the model's mismatch alone. Plain NumPy; no Exudyn.
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

#: What a loop short of :data:`~controllers.loop_design.REQUIRED_MARGINS` does at ``reset``: "off", not checked;
#: "refuse", a SceneError; "feed_forward", no correction in that run, and a warning.
MARGIN_CHECKS = ("off", "refuse", "feed_forward")


def _rotation_coordinates(matrix: np.ndarray) -> np.ndarray:
    """The rotation's coordinates of a rotation matrix: the angle (1,) [rad] of a 2 x 2 one, the rotation
    vector (3,) [rad] of a 3 x 3 one."""
    if matrix.shape == (2, 2):
        return np.array([np.arctan2(matrix[1, 0], matrix[0, 0])])
    return rotation_vector(matrix)


class FilteredPositionPI:
    """PI correction of the winch lengths from the low-pass filtered platform position error.

    Parameters
    ----------
    proportional_gain : float [-]
        k_p, >= 0.
    integral_gain : float [1/s]
        k_i, >= 0.
    cutoff : float [Hz]
        Cut-off frequency of the error filter (> 0).
    start_time : float [s]
        The feedback and its integral fade in over this time from t = 0 (>= 0).
    rotation : bool
        Feed the rotation error back too (a rigid platform only); otherwise the position alone. The
        spatial closed loop of the registry does (:mod:`controllers.registry`), with lower gains than
        these defaults (0.5, 5 /s, 2 Hz): the shipped spatial scenes step at 10 ms and the loop acts one
        step late; with the planar gains the IPAnema circle oscillated from 1 s and the run failed at 2 s
        (217 mm).

    margin_check : {"off", "refuse", "feed_forward"}
        What a loop short of the required margins does at ``reset`` (see above; :data:`MARGIN_CHECKS`). "off"
        (no check) keeps today's runs: today's planar gains keep 28 deg on the paper's circle at t = 1 s.

    Raises
    ------
    SceneError
        If an option is not finite or out of its range; the message names it. At ``reset``, with
        ``margin_check = "refuse"``, if the loop keeps less than the required margins on the scene.
    """

    #: Damping ratio of the second-order error filter (Butterworth).
    FILTER_DAMPING = np.sqrt(0.5)

    def __init__(self, proportional_gain: float = 2.0, integral_gain: float = 40.0, cutoff: float = 5.0,
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
        """Start a run of ``scene`` with the filter and the integral at zero, its margins checked (``margin_check``).

        Raises
        ------
        SceneError
            With ``margin_check = "refuse"``, for a loop short of the required margins, naming its gains and margins.
        """
        self._scene, self.margins, self.off = scene, None, False
        if self.margin_check != "off" and loop_design.models(scene) and not self._with_rotation(scene):
            gains = loop_design.LoopGains(self.proportional_gain, self.integral_gain, self.cutoff)
            self.margins = loop_design.check_loop(scene, gains)
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
        # (time, filtered error, its rate, integral of the filtered error): one entry per call.
        self._history = [(0.0, np.zeros(size), np.zeros(size), np.zeros(size))]

    @property
    def integral(self) -> np.ndarray:
        """Integral of the filtered error at the last call [m s, rad s], shape (error_size,)."""
        return self._history[-1][3]

    def _with_rotation(self, scene) -> bool:
        return self.rotation and not scene.platform.is_point_mass

    def error_size(self, scene) -> int:
        """Length of the error vector the loop filters: the position's (2 | 3), and with ``rotation`` (a rigid
        platform) the rotation's too (+1 | +3)."""
        space = scene.space
        return space.position_size + (space.rotation_size if self._with_rotation(scene) else 0)

    def target(self, time: float) -> np.ndarray:
        """The scene's reference pose at ``time`` [s] [m, rad]."""
        return np.asarray(self._scene.trajectory.pose(time), dtype=float)

    def error(self, goal: np.ndarray, pose: np.ndarray) -> np.ndarray:
        """The error e = (r_goal - r, phi), R(phi) = R_goal R^T the rotation from the measured orientation to
        the goal's (with ``rotation``), for the target ``goal`` and the measured ``pose``, shape (error_size,)."""
        space = self._scene.space
        size = space.position_size
        position = goal[:size] - pose[:size]
        if not self._with_rotation(self._scene):
            return position
        turn = space.rotation_matrix(goal[size:]) @ space.rotation_matrix(pose[size:]).T
        return np.concatenate([position, _rotation_coordinates(turn)])

    def jacobian(self, pose: np.ndarray) -> np.ndarray:
        """d(lambda)/d(the error's coordinates) of the ideal cables at ``pose``, shape (m, error_size) [m/m, m/rad]:
        the first columns of the length Jacobian ``-A^T`` (:func:`cdpr_exu.statics.kinematics.length_jacobian`;
        moving an anchor by d changes the ideal length by u . d, u the unit vector from the cable's exit
        towards the anchor; turning the platform by a small rotation phi moves anchor i by ``phi x R b_i``)."""
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
            rate += h * (omega**2 * (error - filtered) - 2.0 * self.FILTER_DAMPING * omega * rate)
            filtered += h * rate
        integral = integral + filtered * dt * weight
        history.append((time, filtered, rate, integral))
        if len(history) > 64:  # retries reach back one step: a short history is enough
            del history[:-16]
        return filtered, integral

    def correction(self, measurement: Measurement, target: Callable[[float], np.ndarray] | None = None) -> np.ndarray:
        """Length correction dlambda at ``measurement.time``, shape (m,) [m].

        The error is the target minus the measured position, both at the time the pose
        was measured (``measurement.state_time``: the solver's state is one step old
        when it asks for the command; comparing it with the target one step later would
        add a bias of the velocity times the step, 1.2 mm at 0.6 m/s and 2 ms).

        Parameters
        ----------
        measurement : Measurement
            With the platform pose.
        target : callable, optional
            ``target(t)``: the position (x, z) [m] the loop holds the platform to at time
            t [s]; by default the scene's reference. The Jacobian is taken at the
            reference pose either way.

        Raises
        ------
        SceneError
            If the measurement carries no platform pose.
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
        # The integral and the feedback fade in with the start-up blend (weight 0 at t = 0,
        # 1 from start_time on): switched on at once, the winch speed jumps and the axially
        # over-damped winch element pushes (-62 N measured at the switch with spring cables).
        weight = float(quintic_blend(measurement.time / self.start_time)[0]) if self.start_time > 0 else 1.0
        filtered, integral = self._advance(measurement.time, error, weight)
        feedback = weight * (self.proportional_gain * filtered + self.integral_gain * integral)
        return self.jacobian(reference) @ feedback


#: What :class:`ClosedLoopController` holds the platform to: "expected", the path the
#: feed-forward's commands gave on the controller's model (the loop then corrects only
#: the plant's departure from the model), or "reference", the reference itself.
FOLLOW = ("expected", "reference")


class ClosedLoopController:
    """An open-loop controller (the feed-forward) plus :class:`FilteredPositionPI` feedback.

    The command is the feed-forward's paid-out lengths plus the feedback's correction;
    the rate is the feed-forward's.

    With ``follow = "expected"`` the loop holds the platform to the path the feed-forward
    expects (its ``expected_position(t)``: for lengths learned on the controller's model,
    the path they gave there), not to the reference. Where the plant is the model, the
    error it sees is zero and the commands are the feed-forward's alone: the loop acts
    only on what the model gets wrong, and leaves the feed-forward's own residual (the
    cables' fast modes, which the loop, acting late, would amplify) to the feed-forward.
    Measured on paper-circle-mismatch (10 s, 1 s ramp, errors after 1 s; the lengths
    learned in 10 trials on the model, where they leave 2.87 mm; open loop on the plant
    10.2 mm): following the reference, 4.11 mm and 0.30 s with a slack element;
    following the expected path, 2.26 mm and 0.01 s. On paper-circle, whose plant is
    the model: 3.55 mm (0.58 s slack) against 2.88 mm, the feed-forward's own 2.87 mm.

    Parameters
    ----------
    name : str
        Name in reports.
    feed_forward : Controller
        Open loop (``uses_pose`` and ``uses_tension`` False), e.g. a
        :class:`~controllers.ilc.LearnedController`.
    feedback : FilteredPositionPI
    follow : {"expected", "reference"}
        See above (:data:`FOLLOW`).

    Raises
    ------
    SceneError
        If ``feed_forward`` reads the pose or the tensions itself, ``feedback`` is not a
        :class:`FilteredPositionPI` or ``follow`` is not one of :data:`FOLLOW`; at
        ``reset``, if ``follow = "expected"`` and the feed-forward expects no path.
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
        """The feed-forward's learner, if it has one (its trials are reported by ``cdpr compare``)."""
        return getattr(self.feed_forward, "learner", None)

    def reset(self, scene, initial_paid_out) -> None:
        """Reset the feed-forward (a learned one runs its trials here) and the feedback."""
        self.feed_forward.reset(scene, initial_paid_out)
        if self.follow == "expected":
            expected = getattr(self.feed_forward, "expected_position", None)
            if expected is None or expected(0.0) is None:
                raise SceneError(f"follow = 'expected' needs a feed-forward that expects a path (expected_position), "
                                 f"{shown(getattr(self.feed_forward, 'name', self.feed_forward))} does not")
        self.feedback.reset(scene)

    def command(self, measurement: Measurement) -> WinchCommand:
        feed_forward = self.feed_forward.command(measurement)
        target = self.feed_forward.expected_position if self.follow == "expected" else None
        correction = self.feedback.correction(measurement, target)
        return WinchCommand(np.asarray(feed_forward.paid_out, dtype=float) + correction,
                            np.asarray(feed_forward.paid_out_rate, dtype=float))
