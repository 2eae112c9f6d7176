"""Iterative learning control (ILC) of the winch lengths, and the open-loop replay of learned commands.

Trial k runs the robot open loop with lambda_k(t); its position error e_k = r_ref - r_k [m]
updates the lengths (Bristow, Tharayil and Alleyne, IEEE Control Systems 26(3), 2006):

    c_{k+1} = Q(c_k + gamma J(t) e_k(t + tau)),    lambda_k(t) = lambda_0(t) + w(t) c_k(t)

lambda_0 the ideal inverse kinematics (the first trial); J (m, d) [m/m] the ideal length
Jacobian's position columns at the reference pose; gamma the gain; tau a lead (the platform
answers late; the update is not causal); Q a zero-phase Butterworth low-pass that stops the
learning where the response differs too much from J^-1 to converge; w(t) a quintic fade-in
over ``fade_time`` so the commands keep lambda_0's start. How gamma, tau and the cut-off were
chosen: :mod:`cdpr_exu.studies.learning`. :class:`LearnedController` asks an injected learner
for its table (controllers never run simulations). Plain NumPy/SciPy.
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

from .base import Measurement, WinchCommand, quintic_blend


def fade_in(times: np.ndarray, fade_time: float) -> np.ndarray:
    """Quintic fade (N,) from 0 at t = 0 to 1 at ``fade_time`` [s] (0: ones) on ``times`` (N,) [s]."""
    times = np.asarray(times, dtype=float)
    return np.ones_like(times) if fade_time <= 0 else quintic_blend(times / fade_time)[0]


def position_jacobian(scene, poses: np.ndarray) -> np.ndarray:
    """Length change of each ideal cable per platform position change at ``poses`` (N, w), rotation held:
    the position columns of :func:`cdpr_exu.statics.kinematics.length_jacobian`, shape (N, m, d) [m/m]."""
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    return length_jacobian(scene, poses)[..., :scene.space.position_size]


def ideal_changes(scene, times: np.ndarray) -> np.ndarray:
    """Change of the ideal paid-out lengths since t = 0 along ``scene.trajectory``, shape (N, m) [m]."""
    lengths, _ = ideal_paid_out(scene, scene.trajectory.pose(np.asarray(times, dtype=float)))
    return lengths - lengths[0]


@dataclass(frozen=True)
class CommandTable:
    """Winch commands as changes (N, m) [m] of the paid-out lengths since t = 0 on ``times`` (N,) [s],
    increasing from 0; ``expected_poses`` (N, w) [m, rad]: the platform poses they gave where they were
    learned (the result's pose: position, then rotation), if known (what a feedback around them should expect)."""

    times: np.ndarray
    changes: np.ndarray
    expected_poses: np.ndarray | None = None

    def __post_init__(self) -> None:
        times = np.asarray(self.times, dtype=float)
        changes = np.asarray(self.changes, dtype=float)
        if times.ndim != 1 or len(times) < 4 or not np.all(np.diff(times) > 0) or abs(times[0]) > 1e-12:
            raise SceneError(f"times must be at least 4 increasing times from 0 [s], got shape {times.shape}")
        if changes.ndim != 2 or changes.shape[0] != len(times) or not np.all(np.isfinite(changes)):
            raise SceneError(f"changes must be finite, shape ({len(times)}, m), got shape {changes.shape}")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "changes", changes)
        if self.expected_poses is not None:
            expected = np.asarray(self.expected_poses, dtype=float)
            if expected.ndim != 2 or expected.shape[0] != len(times) or not np.all(np.isfinite(expected)):
                raise SceneError(f"expected_poses must be finite, shape ({len(times)}, w), "
                                 f"got shape {expected.shape}")
            object.__setattr__(self, "expected_poses", expected)

    def to_dict(self) -> dict:
        """Plain-data form (JSON-ready)."""
        data = {"times_s": self.times.tolist(), "changes_m": self.changes.tolist()}
        if self.expected_poses is not None:
            data["expected_poses_m_rad"] = self.expected_poses.tolist()
        return data


class ReplayController:
    """Open-loop replay of a :class:`CommandTable` (cubic spline; its derivative is the rate)."""

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
        expected = self.table.expected_poses
        self._expected = None if expected is None else CubicSpline(self.table.times, expected, axis=0)

    def expected_pose(self, time: float) -> np.ndarray | None:
        """The pose [m, rad] the commands gave where they were learned, at ``time`` [s]; None if unknown."""
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
    """The ILC update (module notes): ``gain`` gamma in (0, 2), ``lead`` tau >= 0 [s], Q's ``cutoff`` [Hz] and
    Butterworth ``filter_order`` (run twice by filtfilt), the fade-in's ``fade_time`` [s]."""

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
        """The next correction c_{k+1} (N, m) [m] from c_k (N, m) [m] (before the fade), the position errors
        r_ref - r (N, d) [m] on the uniform ``times`` (N,) [s] and :func:`position_jacobian` (N, m, d)."""
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
    """When to stop learning: after ``max_trials`` (>= 1, the first included), or once a trial's max error
    has risen or fallen by less than the fraction ``min_improvement`` (in [0, 1))."""

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
    """Open-loop replay of what ``learner(scene, initial_paid_out) -> CommandTable`` computes at reset."""

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
