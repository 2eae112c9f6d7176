"""Iterative learning control (ILC) of the winch lengths, and the open-loop replay of learned commands.

A repeated task (the same reference, run after run) lets a controller learn from the
error of its last trial. Trial k runs the robot open loop with the paid-out lengths
lambda_k(t); the measured platform position error e_k(t) = r_ref(t) - r_k(t) [m]
updates the lengths for the next trial (Bristow, Tharayil and Alleyne, "A survey of
iterative learning control", IEEE Control Systems 26(3), 2006):

    c_{k+1} = Q(c_k + gamma J(t) e_k(t + tau)),    lambda_k(t) = lambda_0(t) + w(t) c_k(t)

* lambda_0 : the ideal inverse kinematics (:mod:`controllers.ideal_ik`), the first trial;
* J(t), shape (m, d) [m/m] : the ideal cables' length change per platform position change
  (d = 2 in the plane, 3 in space: the one kinematics' length Jacobian, its position columns)
  at the reference pose (rotation held), so that a correction J d moves the platform by
  about d;
* gamma [-] : the learning gain;
* tau [s] : a time advance (lead) of the error, which the non-causal update can afford:
  the platform answers a length change late;
* Q : a zero-phase low-pass (a Butterworth filter run forwards and backwards,
  :func:`scipy.signal.filtfilt`): it stops the learning where the robot's response
  differs too much from J^-1 for the update to converge (its pendulum, rotation and cable
  modes), at the price of a small residual error there;
* w(t) : a smooth (quintic) fade-in from 0 at t = 0 to 1 at ``fade_time``: the
  correction starts at zero, so the learned commands keep the start of lambda_0 and
  never jump. The error before ``fade_time`` is weighted by w too.

How gamma, tau and the cut-off were chosen (from the frequency response of the
controller's model, measured on the simulator) is in :mod:`cdpr_exu.studies.learning`.
A :class:`StoppingRule` ends the trials when the maximum error stops falling.

:class:`ReplayController` replays a table of learned commands open loop through the
:class:`~controllers.base.Controller` interface; :class:`LearnedController` asks an
injected learner (which runs the trials; controllers never run simulations themselves)
for that table when it is reset. Plain NumPy/SciPy; no Exudyn.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.signal import butter, filtfilt

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import shown
from cdpr_exu.statics.kinematics import ideal_paid_out, length_jacobian

from .base import Measurement, WinchCommand


def fade_in(times: np.ndarray, fade_time: float) -> np.ndarray:
    """Quintic fade from 0 at t = 0 to 1 at ``fade_time`` [s] (zero slope and curvature at both ends).

    Parameters
    ----------
    times : ndarray, shape (N,) [s]
    fade_time : float [s]; 0 gives ones.

    Returns
    -------
    ndarray, shape (N,) [-]
    """
    times = np.asarray(times, dtype=float)
    if fade_time <= 0:
        return np.ones_like(times)
    s = np.clip(times / fade_time, 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s**2)


def position_jacobian(scene, poses: np.ndarray) -> np.ndarray:
    """Length change of each ideal cable per platform position change, rotation held.

    Moving the anchors by d changes the ideal paid-out length of cable i by u_i . d,
    u_i the unit vector from the cable's exit point to its anchor: the position columns of
    :func:`cdpr_exu.statics.kinematics.length_jacobian`.

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene
    poses : ndarray, shape (N, pose_size) [m, rad]

    Returns
    -------
    ndarray, shape (N, m, position_size) [m/m]
    """
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    return length_jacobian(scene, poses)[..., :scene.space.position_size]


def ideal_changes(scene, times: np.ndarray) -> np.ndarray:
    """Change of the ideal paid-out lengths since t = 0 along ``scene.trajectory``, shape (N, m) [m]."""
    lengths, _ = ideal_paid_out(scene, scene.trajectory.pose(np.asarray(times, dtype=float)))
    return lengths - lengths[0]


@dataclass(frozen=True)
class CommandTable:
    """Winch commands as changes of the paid-out lengths since t = 0, on a time grid.

    Attributes
    ----------
    times : ndarray, shape (N,) [s]
        Increasing, from 0.
    changes : ndarray, shape (N, m) [m]
        Paid-out length of each winch minus what it paid out at t = 0 (zero in the first row).
    expected_positions : ndarray, shape (N, d), or None [m]
        The platform position ((x, z) or (x, y, z)) these commands gave where they were learned (the
        controller's model, for model-based feed-forward), if known: what a feedback
        around them should expect of a plant that matches the model.
    """

    times: np.ndarray
    changes: np.ndarray
    expected_positions: np.ndarray | None = None

    def __post_init__(self) -> None:
        times = np.asarray(self.times, dtype=float)
        changes = np.asarray(self.changes, dtype=float)
        if times.ndim != 1 or len(times) < 4 or not np.all(np.diff(times) > 0) or abs(times[0]) > 1e-12:
            raise SceneError(f"times must be at least 4 increasing times from 0 [s], got shape {times.shape}")
        if changes.ndim != 2 or changes.shape[0] != len(times) or not np.all(np.isfinite(changes)):
            raise SceneError(f"changes must be finite, shape ({len(times)}, m), got shape {changes.shape}")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "changes", changes)
        if self.expected_positions is not None:
            expected = np.asarray(self.expected_positions, dtype=float)
            if expected.ndim != 2 or expected.shape[0] != len(times) or not np.all(np.isfinite(expected)):
                raise SceneError(f"expected_positions must be finite, shape ({len(times)}, d), "
                                 f"got shape {expected.shape}")
            object.__setattr__(self, "expected_positions", expected)

    def to_dict(self) -> dict:
        """Plain-data form (JSON-ready)."""
        data = {"times_s": self.times.tolist(), "changes_m": self.changes.tolist()}
        if self.expected_positions is not None:
            data["expected_positions_m"] = self.expected_positions.tolist()
        return data


class ReplayController:
    """Open-loop replay of a :class:`CommandTable` (cubic spline; its derivative is the rate).

    Parameters
    ----------
    table : CommandTable
    name : str
        Name in reports.
    """

    uses_pose = False
    uses_tension = False

    def __init__(self, table: CommandTable, name: str = "replay"):
        if not isinstance(table, CommandTable):
            raise SceneError(f"table must be a CommandTable, got {type(table).__name__}")
        self.table = table
        self.name = name
        self._spline = None

    def reset(self, scene, initial_paid_out) -> None:
        """Check the table fits ``scene`` (cables, end time) and build the spline."""
        initial = np.asarray(initial_paid_out, dtype=float)
        if self.table.changes.shape[1] != len(initial):
            raise SceneError(f"the command table has {self.table.changes.shape[1]} cables, the scene {len(initial)}")
        if self.table.times[-1] < scene.solver.end_time - 1e-9:
            raise SceneError(f"the command table ends at {self.table.times[-1]:g} s, before solver.end_time = "
                             f"{scene.solver.end_time:g} s")
        self._spline = CubicSpline(self.table.times, initial + self.table.changes, axis=0)
        self._rate = self._spline.derivative()
        expected = self.table.expected_positions
        self._expected = None if expected is None else CubicSpline(self.table.times, expected, axis=0)

    def expected_position(self, time: float) -> np.ndarray | None:
        """The platform position ((x, z) or (x, y, z)) [m] the table's commands gave where they were learned, at
        ``time`` [s]; None if the table does not say."""
        if self._spline is None:
            raise RuntimeError(f"{type(self).__name__}.reset(scene, initial_paid_out) must be called first")
        return None if self._expected is None else np.asarray(self._expected(time))

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._spline is None:
            raise RuntimeError(f"{type(self).__name__}.reset(scene, initial_paid_out) must be called first")
        t = measurement.time
        return WinchCommand(np.asarray(self._spline(t)), np.asarray(self._rate(t)))


@dataclass(frozen=True)
class LearningLaw:
    """The ILC update c_{k+1} = Q(c_k + gamma J e_k(t + tau)) (see the module notes).

    Parameters
    ----------
    gain : float [-]
        Learning gain gamma, in (0, 2).
    lead : float [s]
        Time advance tau of the error, >= 0.
    cutoff : float [Hz]
        Cut-off of the zero-phase Butterworth low-pass Q.
    filter_order : int
        Order of the Butterworth filter (run twice by filtfilt: twice the roll-off).
    fade_time : float [s]
        Duration of the fade-in w(t) of the correction and of the error weight.
    """

    gain: float = 0.5
    lead: float = 0.0
    cutoff: float = 2.0
    filter_order: int = 2
    fade_time: float = 0.5

    def __post_init__(self) -> None:
        if not np.isfinite(self.gain) or not 0.0 < self.gain < 2.0:
            raise SceneError(f"gain must lie in (0, 2), got {shown(self.gain)}")
        if not np.isfinite(self.lead) or self.lead < 0:
            raise SceneError(f"lead must be zero or positive [s], got {shown(self.lead)}")
        if not np.isfinite(self.cutoff) or self.cutoff <= 0:
            raise SceneError(f"cutoff must be positive [Hz], got {shown(self.cutoff)}")
        if isinstance(self.filter_order, bool) or not isinstance(self.filter_order, (int, np.integer)) \
                or not 1 <= self.filter_order <= 8:
            raise SceneError(f"filter_order must be an integer from 1 to 8, got {shown(self.filter_order)}")
        if not np.isfinite(self.fade_time) or self.fade_time < 0:
            raise SceneError(f"fade_time must be zero or positive [s], got {shown(self.fade_time)}")

    def low_pass(self, signal: np.ndarray, sample_time: float) -> np.ndarray:
        """Q: zero-phase low-pass of ``signal`` (shape (N, ...)) along time, sampled every ``sample_time`` [s]."""
        nyquist = 0.5 / sample_time
        if self.cutoff >= nyquist:
            raise SceneError(f"cutoff = {self.cutoff} Hz must lie below the Nyquist frequency {nyquist:g} Hz "
                             f"of the {sample_time:g} s samples")
        b, a = butter(self.filter_order, self.cutoff / nyquist)
        return filtfilt(b, a, signal, axis=0)

    def update(self, times: np.ndarray, correction: np.ndarray, errors: np.ndarray,
               jacobians: np.ndarray) -> np.ndarray:
        """The next trial's correction c_{k+1}.

        Parameters
        ----------
        times : ndarray, shape (N,) [s]
            Uniform grid from 0.
        correction : ndarray, shape (N, m) [m]
            This trial's correction c_k (before the fade).
        errors : ndarray, shape (N, d) [m]
            This trial's position error r_ref - r on ``times`` (d: 2 planar, 3 spatial).
        jacobians : ndarray, shape (N, m, d) [m/m]
            :func:`position_jacobian` at the reference poses.

        Returns
        -------
        ndarray, shape (N, m) [m]
        """
        times = np.asarray(times, dtype=float)
        weighted = fade_in(times, self.fade_time)[:, None] * np.asarray(errors, dtype=float)
        if self.lead > 0:  # e(t + tau); held at its last value beyond the end
            weighted = np.column_stack([np.interp(times + self.lead, times, column)
                                        for column in weighted.T])
        step = np.einsum("nij,nj->ni", jacobians, weighted)
        return self.low_pass(np.asarray(correction, dtype=float) + self.gain * step, times[1] - times[0])

    def commands(self, times: np.ndarray, baseline: np.ndarray, correction: np.ndarray) -> CommandTable:
        """lambda_k = lambda_0 + w c_k as a :class:`CommandTable` (``baseline``: lambda_0's changes, (N, m) [m])."""
        weight = fade_in(times, self.fade_time)[:, None]
        return CommandTable(times, baseline + weight * correction)


@dataclass(frozen=True)
class StoppingRule:
    """When to stop learning.

    Trials stop after ``max_trials``, or as soon as the maximum position error of a
    trial has fallen by less than ``min_improvement`` (a fraction) from the previous
    trial's, or has risen. The best trial's commands are the ones kept.

    Parameters
    ----------
    max_trials : int
        Most trials, the first (ideal IK) included, >= 1.
    min_improvement : float [-]
        In [0, 1).
    """

    max_trials: int = 10
    min_improvement: float = 0.02

    def __post_init__(self) -> None:
        if isinstance(self.max_trials, bool) or not isinstance(self.max_trials, (int, np.integer)) \
                or self.max_trials < 1:
            raise SceneError(f"max_trials must be an integer >= 1, got {shown(self.max_trials)}")
        if not np.isfinite(self.min_improvement) or not 0.0 <= self.min_improvement < 1.0:
            raise SceneError(f"min_improvement must lie in [0, 1), got {shown(self.min_improvement)}")

    def reason_to_stop(self, max_errors: list[float]) -> str | None:
        """Why to stop after the trials whose maximum errors [m] are ``max_errors``, or None to go on."""
        if len(max_errors) >= self.max_trials:
            return f"max_trials = {self.max_trials} reached"
        if len(max_errors) >= 2:
            last, before = max_errors[-1], max_errors[-2]
            if last > before:
                return f"the max error rose ({1000 * before:.3g} -> {1000 * last:.3g} mm)"
            if before - last < self.min_improvement * before:
                return (f"the max error fell by less than min_improvement = {self.min_improvement:g} "
                        f"({1000 * before:.3g} -> {1000 * last:.3g} mm)")
        return None


class LearnedController(ReplayController):
    """Open-loop replay of commands that an injected learner computes when the run is reset.

    Parameters
    ----------
    name : str
    learner : callable
        ``learner(scene, initial_paid_out) -> CommandTable``; it may run trials on a
        simulator (the caller supplies it: controllers never run simulations).
    """

    def __init__(self, name: str, learner: Callable):
        if not callable(learner):
            raise SceneError(f"learner must be callable, got {shown(learner)}")
        self.name = name
        self.learner = learner
        self.table = None
        self._spline = None

    def reset(self, scene, initial_paid_out) -> None:
        """Learn the commands for ``scene`` and prepare their replay."""
        self.table = self.learner(scene, np.asarray(initial_paid_out, dtype=float))
        if not isinstance(self.table, CommandTable):
            raise SceneError(f"the learner of {shown(self.name)} must return a CommandTable, got {type(self.table).__name__}")
        super().reset(scene, initial_paid_out)
