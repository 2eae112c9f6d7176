"""Iterative learning control of the winch lengths: the learning law, its options and the replay, without a simulation."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import load_scene
from controllers import IdealIKController, Measurement
from cdpr_exu.statics.kinematics import ideal_paid_out
from controllers.ilc import (CommandTable, LearnedController, LearningLaw, ReplayController, StoppingRule, fade_in,
                             ideal_changes, position_jacobian)

PAPER = load_scene("paper-circle")


def test_fade_in_starts_at_zero_with_zero_slope_and_reaches_one():
    times = np.array([0.0, 1e-3, 0.25, 0.5, 2.0])
    weight = fade_in(times, 0.5)
    assert weight[0] == 0.0 and weight[1] < 1e-7  # quintic: ~10 (t/T)^3 = 8e-8
    assert weight[2] == pytest.approx(0.5) and weight[3] == 1.0 and weight[4] == 1.0


def test_position_jacobian_is_the_derivative_of_the_ideal_lengths_with_rotation_held():
    pose = np.array([0.2, -1.7, 0.1])
    jacobian = position_jacobian(PAPER, pose[None, :])[0]
    step = 1e-6
    for axis in range(2):
        moved = pose.copy()
        moved[axis] += step
        difference = (ideal_paid_out(PAPER, moved[None, :])[0][0] - ideal_paid_out(PAPER, pose[None, :])[0][0]) / step
        np.testing.assert_allclose(jacobian[:, axis], difference, atol=1e-5)  # forward difference: O(step / length)


def test_replaying_the_ideal_changes_gives_the_ideal_ik_commands():
    scene = PAPER.with_changes(solver=replace(PAPER.solver, end_time=2.0))
    grid = np.linspace(0.0, 2.0, 201)
    initial = np.array([3.0, 3.2])
    replay = ReplayController(CommandTable(grid, ideal_changes(scene, grid)))
    ideal = IdealIKController()
    replay.reset(scene, initial)
    ideal.reset(scene, initial)
    for t in np.linspace(0.05, 1.95, 20):
        measurement = Measurement(t, initial, np.zeros(2))
        # The cubic spline on a 10 ms grid against linear interpolation on the 2 ms step grid:
        # curvature of the lengths ~1 m/s^2 gives (2e-3)^2 / 8 ~ 5e-7 m.
        np.testing.assert_allclose(replay.command(measurement).paid_out, ideal.command(measurement).paid_out, atol=2e-6)


def test_one_update_on_a_static_plant_shrinks_a_slow_error_by_one_minus_the_gain():
    """A plant whose platform moves by exactly J^-1 dlambda (the ideal cables) is answered at once:
    the next error is (1 - gamma) e where Q passes the error and the fade is 1."""
    times = np.linspace(0.0, 10.0, 1001)
    jacobians = position_jacobian(PAPER, PAPER.trajectory.pose(times))
    law = LearningLaw(gain=0.7, lead=0.0, cutoff=5.0, fade_time=0.5)
    error = 0.01 * np.column_stack([np.sin(1.5 * times), np.cos(3.0 * times)])  # the circle's first harmonics
    correction = law.update(times, np.zeros((len(times), 2)), error, jacobians)
    moved = np.linalg.solve(jacobians, (fade_in(times, 0.5)[:, None] * correction)[..., None])[..., 0]  # platform motion J^-1 w c
    inside = (times >= 1.0) & (times <= 9.0)
    # Q at 0.24 and 0.48 Hz passes 1 - 1e-5 (2e-7 m here); filtfilt's edge transient (odd padding)
    # reaches 0.7 % of the 10 mm error in the last second only.
    np.testing.assert_allclose((error - moved)[inside], (1 - 0.7) * error[inside], atol=2e-6)
    np.testing.assert_allclose((error - moved)[times > 9.0], (1 - 0.7) * error[times > 9.0], atol=1e-4)


@pytest.mark.parametrize("options, name", [
    ({"gain": 0.0}, "gain"), ({"gain": 2.0}, "gain"), ({"gain": float("nan")}, "gain"),
    ({"lead": -0.01}, "lead"), ({"cutoff": 0.0}, "cutoff"), ({"filter_order": 0}, "filter_order"),
    ({"filter_order": 2.5}, "filter_order"), ({"fade_time": -1.0}, "fade_time")])
def test_bad_learning_law_options_are_refused_by_name(options, name):
    with pytest.raises(SceneError, match=name):
        LearningLaw(**options)


@pytest.mark.parametrize("options, name", [({"max_trials": 0}, "max_trials"), ({"max_trials": 2.0}, "max_trials"),
                                           ({"min_improvement": 1.0}, "min_improvement"),
                                           ({"min_improvement": -0.1}, "min_improvement")])
def test_bad_stopping_rule_options_are_refused_by_name(options, name):
    with pytest.raises(SceneError, match=name):
        StoppingRule(**options)


def test_a_cutoff_above_the_nyquist_frequency_is_refused_by_name():
    with pytest.raises(SceneError, match="cutoff"):
        LearningLaw(cutoff=60.0).low_pass(np.zeros((100, 2)), 0.01)


def test_stopping_rule_stops_on_a_rise_a_stall_or_the_trial_count():
    rule = StoppingRule(max_trials=4, min_improvement=0.05)
    assert rule.reason_to_stop([0.07]) is None
    assert rule.reason_to_stop([0.07, 0.03]) is None
    assert "rose" in rule.reason_to_stop([0.07, 0.03, 0.031])
    assert "min_improvement" in rule.reason_to_stop([0.07, 0.03, 0.029])
    assert "max_trials" in rule.reason_to_stop([0.07, 0.03, 0.01, 0.005])


def test_a_table_that_ends_before_the_run_is_refused_naming_the_end_time():
    grid = np.linspace(0.0, 2.0, 21)
    with pytest.raises(SceneError, match="end_time"):
        ReplayController(CommandTable(grid, np.zeros((21, 2)))).reset(PAPER, np.array([3.0, 3.0]))


def test_a_learner_that_returns_no_table_is_refused():
    with pytest.raises(SceneError, match="CommandTable"):
        LearnedController("broken", lambda scene, initial: None).reset(PAPER, np.array([3.0, 3.0]))
