"""Learning the winch lengths over repeated trials: iterative learning control and model-based feed-forward.

:func:`learn_lengths` runs iterative learning control (:mod:`controllers.ilc`) on a scene,
from the ideal inverse kinematics until the stopping rule ends it. :func:`model_feed_forward`
learns on the controller's *model* and runs the learned lengths open loop on the *plant*.

How the default learning law was chosen (:data:`DEFAULT_LAW`)
-------------------------------------------------------------
c_{k+1} = Q(c_k + gamma J e_k(t + tau)) converges monotonically (for a linear time-invariant
approximation) where the largest singular value of Q (I - gamma exp(i omega tau) G) stays
below 1, G the response of the platform position to the command J^-1 dlambda.
:func:`measure_response` measured G on paper-circle (4 mm RMS multisines, 0.11 to 5 Hz):
|G_xx|, |G_zz| within 0.84..1.21 up to 2 Hz, lag up to 50 deg, cross terms up to 0.35, |G_xx|
about 0.5 from 3.4 Hz. The largest singular value of I - gamma exp(i omega tau) G
(``examples/learning_control.py``):

======= ========= ========== ========== ==========
gamma   tau [s]   <= 1 Hz    <= 2 Hz    <= 5 Hz
======= ========= ========== ========== ==========
0.5     0         0.67       0.85       0.85
0.7     0         0.54       0.84       0.84
0.7     0.02      0.56       0.79       0.80
1.0     0         0.47       1.02       1.02
1.0     0.02      0.44       0.87       0.87
0.7     0.06      0.61       0.88       1.24
======= ========= ========== ========== ==========

gamma = 0.7 with a 20 ms lead keeps it at or below 0.8 over the band and shrinks the
errors below 1 Hz (most of the circle's) by about 0.56 per trial. Q cuts off at 5 Hz, the
band's end (|Q| = 0.06 at 10 Hz, where the cables' modes begin); at 3 Hz the mismatch
plant's error stalled at 4.2 mm, its residual at 1.7-4.5 Hz. A 10 % mismatch of platform
mass and cable density moves G far less than the 0.2 margin.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np

from controllers.ilc import (CommandTable, LearningLaw, ReplayController, StoppingRule, fade_in, ideal_changes,
                             position_jacobian)

from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.results.result import Result
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import Scene

#: The learning law designed from the measured response of the paper-circle model (module notes).
DEFAULT_LAW = LearningLaw(gain=0.7, lead=0.02, cutoff=5.0, filter_order=2, fade_time=0.5)
#: Ten trials at most; stop when the max error falls by less than 2 % or rises.
DEFAULT_RULE = StoppingRule(max_trials=10, min_improvement=0.02)


@dataclass(frozen=True)
class Trial:
    """What one learning trial (1: the ideal IK) measured after ``after`` seconds: errors [m], the lowest
    element tension [N], the longest slack time of a cable [s], and its largest correction over the
    ideal IK [m]."""

    number: int
    max_position_error_m: float | None
    rms_position_error_m: float | None
    min_element_tension_N: float | None
    slack_time_s: float | None
    max_correction_m: float
    status: str

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class LearningRun:
    """The trials of one learning; ``table`` and ``result``: the best trial's (lowest max error) commands,
    with the poses they gave (``expected_poses``), and run."""

    trials: list[Trial]
    table: CommandTable
    best_trial: int
    stop_reason: str
    result: Result
    law: LearningLaw = field(default_factory=lambda: DEFAULT_LAW)

    def to_dict(self) -> dict:
        return {"trials": [t.to_dict() for t in self.trials], "best_trial": self.best_trial,
                "stop_reason": self.stop_reason, "learning_law": dict(self.law.__dict__)}


def command_grid(scene: Scene) -> np.ndarray:
    """The learning's time grid: the scene's output times from 0 to ``solver.end_time``, shape (N,) [s]."""
    solver = scene.solver
    count = int(round(solver.end_time / solver.output_period)) + 1
    return np.linspace(0.0, solver.end_time, count)


def position_errors(result: Result, times: np.ndarray) -> np.ndarray:
    """Position error r_ref - r of ``result`` interpolated on ``times``, shape (N, d) [m]."""
    error = -result.position_error
    return np.column_stack([np.interp(times, result.time, column) for column in error.T])


def _trial(number: int, result: Result, correction: float, after: float) -> Trial:
    summary = result.summary(after=after)
    slack = [s for s in summary["slack_time_per_cable_s"] if s is not None]
    return Trial(number, summary["max_position_error_m"], summary["rms_position_error_m"],
                 summary["min_element_tension_N"], max(slack) if slack else None, correction, result.status)


def trial_line(trial: Trial) -> str:
    """One line on a trial, as ``cdpr compare`` shows the learning's progress."""
    def mm(value):
        return "   n/a" if value is None else f"{1000 * value:6.2f}"
    tension = "n/a" if trial.min_element_tension_N is None else f"{trial.min_element_tension_N:.2f}"
    return (f"  trial {trial.number:2d}: max {mm(trial.max_position_error_m)} mm, RMS {mm(trial.rms_position_error_m)} mm, "
            f"min tension {tension} N, correction {mm(trial.max_correction_m)} mm  {trial.status}")


def _check_settings(law, rule) -> None:
    if not isinstance(law, LearningLaw):
        raise SceneError(f"law must be a LearningLaw, got {law!r}")
    if not isinstance(rule, StoppingRule):
        raise SceneError(f"rule must be a StoppingRule, got {rule!r}")


def learn_lengths(scene: Scene, law: LearningLaw = DEFAULT_LAW, rule: StoppingRule = DEFAULT_RULE, *,
                  after: float = 1.0, on_trial: Callable[[Trial], None] | None = None) -> LearningRun:
    """Iterative learning control of the winch lengths on ``scene`` (the plant, or the controller's model),
    trials until ``rule`` stops them, errors from ``after`` [s] on; ``on_trial(trial)`` after each.

    Raises
    ------
    SceneError
        If ``law``, ``rule`` or ``after`` is not valid, before any trial.
    SolverFailure
        If the first trial fails (a later failure ends the learning).
    """
    _check_settings(law, rule)
    if not np.isfinite(after) or not 0.0 <= after < scene.solver.end_time:
        raise SceneError(f"after must lie in [0, solver.end_time = {scene.solver.end_time}) s, got {after!r}")
    times = command_grid(scene)
    law.low_pass(np.zeros((len(times), 1)), times[1] - times[0])  # refuses a cut-off above Nyquist before any trial
    baseline = ideal_changes(scene, times)
    jacobians = position_jacobian(scene, scene.trajectory.pose(times))
    correction = np.zeros_like(baseline)
    trials: list[Trial] = []
    best = None
    stop_reason = ""
    while True:
        table = law.commands(times, baseline, correction)
        failure = None
        try:
            result = simulate(scene, ReplayController(table, name=f"ilc_trial_{len(trials) + 1}"))
        except SolverFailure as err:
            if not trials:
                raise
            result, failure = err.partial_result, err
        trial = _trial(len(trials) + 1, result, float(np.abs(table.changes - baseline).max()), after)
        trials.append(trial)
        if on_trial is not None:
            on_trial(trial)
        if failure is not None:
            stop_reason = f"trial {trial.number} failed: {failure}"
            break
        if best is None or trial.max_position_error_m < best[0].max_position_error_m:
            expected = np.column_stack([np.interp(times, result.time, column) for column in result.pose.T])
            best = (trial, replace(table, expected_poses=expected), result)
        stop_reason = rule.reason_to_stop([t.max_position_error_m for t in trials])
        if stop_reason is not None:
            break
        correction = law.update(times, correction, position_errors(result, times), jacobians)
    return LearningRun(trials, best[1], best[0].number, stop_reason, best[2], law)


@dataclass(frozen=True)
class PositionResponse:
    """Measured response (F, d, d) [m/m] of the platform position (rows) to the position command J^-1
    dlambda (columns) at ``frequencies`` (F,) [Hz]."""

    frequencies: np.ndarray
    response: np.ndarray

    def contraction(self, gain: float, lead: float) -> np.ndarray:
        """Largest singular value of I - gain exp(i omega lead) G, shape (F,): below 1 where the law
        (without Q) shrinks the error every trial."""
        phase = np.exp(2j * np.pi * self.frequencies * lead)[:, None, None]
        return np.linalg.svd(np.eye(self.response.shape[-1]) - gain * phase * self.response, compute_uv=False)[:, 0]


def measure_response(model: Scene, amplitude: float = 4e-3, max_frequency: float = 5.0, *, after: float = 1.0,
                     seed: int = 1) -> PositionResponse:
    """Measure the platform's position response to small length changes along the reference (d + 1 runs).

    The ideal-IK lengths run as they are, then with J(t) p(t) added, p a random-phase
    multisine along each coordinate in turn (``amplitude`` RMS [m], faded in from 0.5 to 1 s,
    multiples of 1 / (end_time - after) up to ``max_frequency`` [Hz]); the Fourier transforms
    over t >= ``after`` give G, a linear time-invariant summary of a robot that is neither.
    """
    times = command_grid(model)
    window = times >= after - 1e-9
    window[np.flatnonzero(window)[-1]] = False  # an even period: t in [after, end)
    period = times[window][-1] + (times[1] - times[0]) - after
    frequencies = np.arange(1, int(max_frequency * period) + 1) / period
    baseline = ideal_changes(model, times)
    jacobians = position_jacobian(model, model.trajectory.pose(times))

    def positions(changes):
        result = simulate(model, ReplayController(CommandTable(times, changes), name="response"))
        return -position_errors(result, times)

    rest = positions(baseline)
    rng = np.random.default_rng(seed)
    commands, changes = [], []
    for axis in range(model.space.position_size):
        p = sum(np.sin(2 * np.pi * f * times + rng.uniform(0.0, 2 * np.pi)) for f in frequencies)
        p = amplitude * p / np.std(p) * fade_in(times - 0.5, 0.5)
        command = np.zeros((len(times), model.space.position_size))
        command[:, axis] = p
        commands.append(command)
        changes.append(positions(baseline + np.einsum("nij,nj->ni", jacobians, command)) - rest)
    bins = np.rint(frequencies * period).astype(int)
    u = np.stack([np.fft.rfft(c[window], axis=0)[bins] for c in commands], axis=-1)  # (F, d, d experiments)
    y = np.stack([np.fft.rfft(c[window], axis=0)[bins] for c in changes], axis=-1)
    return PositionResponse(frequencies, y @ np.linalg.inv(u))


def model_feed_forward(model: Scene, plant: Scene, law: LearningLaw = DEFAULT_LAW, rule: StoppingRule = DEFAULT_RULE,
                       *, after: float = 1.0, on_trial: Callable[[Trial], None] | None = None
                       ) -> tuple[LearningRun, Result]:
    """Learn the lengths on the controller's ``model``; return that learning and the ``plant``'s open-loop
    run with them. SceneError if the two differ in their number of cables or end time."""
    if model.n_cables != plant.n_cables or model.solver.end_time != plant.solver.end_time:
        raise SceneError("model and plant must have the same number of cables and solver.end_time")
    learning = learn_lengths(model, law, rule, after=after, on_trial=on_trial)
    return learning, simulate(plant, ReplayController(learning.table, name="model_feed_forward"))


class Learner:
    """Learns a :class:`~controllers.ilc.CommandTable` for :class:`~controllers.ilc.LearnedController`, on the
    scene itself (ILC) or ``on_model``, its :meth:`Scene.controller_scene`; ``report`` gets each line of
    the progress. ``learning``: the trials of the last call."""

    def __init__(self, on_model: bool, law: LearningLaw = DEFAULT_LAW, rule: StoppingRule = DEFAULT_RULE, *,
                 after: float = 1.0, report: Callable[[str], None] | None = None, plant: Scene | None = None):
        _check_settings(law, rule)
        self.on_model, self.law, self.rule, self.after, self.report = bool(on_model), law, rule, after, report
        self.plant = plant
        self.learning: LearningRun | None = None

    def __call__(self, scene: Scene, initial_paid_out: np.ndarray) -> CommandTable:  # noqa: ARG002 - same start
        """Learn the commands; ``scene`` is the controllers' model: learning on the robot needs ``plant``."""
        if self.on_model:
            target = (self.plant if self.plant is not None else scene).controller_scene()
        elif self.plant is not None:
            target = self.plant
        elif scene.controller_model is None:
            target = scene
        else:
            raise SceneError("iterative learning on the robot needs the plant (Learner(plant=...)): "
                             "the run hands the controller only the controllers' model")
        report = self.report
        if report is not None:
            where = "the controller's model of " if self.on_model else ""
            report(f"  learning on {where}{scene.name} (at most {self.rule.max_trials} trials)")
        self.learning = learn_lengths(target, self.law, self.rule, after=self.after,
                                      on_trial=None if report is None else (lambda trial: report(trial_line(trial))))
        if report is not None:
            report(f"  kept trial {self.learning.best_trial}: {self.learning.stop_reason}")
        return self.learning.table


def learners(plant: Scene | None = None, rule: StoppingRule = DEFAULT_RULE, law: LearningLaw = DEFAULT_LAW, *,
             after: float = 1.0, report: Callable[[str], None] | None = None) -> Callable[[bool], Learner]:
    """The ``learner`` the registry's learning kinds take: ``learner(on_model)``, a :class:`Learner` of
    ``plant`` with these settings."""
    return lambda on_model: Learner(on_model, law, rule, after=after, report=report, plant=plant)
