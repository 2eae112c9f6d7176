"""One Result for planar and spatial runs (issue 24, step 3): the dimension is data, the summary's figures
are named from the Space's labels, one save/load, and the safety figures (issue 23 follow-up) start
after the initial condition."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.results.result import LEFT_OUT, Result, safety_figures
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.space import PLANE, SPACE

#: A short run of each dimension: the slow paper circle (planar, started smoothly: its cables stay taut)
#: and CoGiRo (spatial), 0.3 s.
SCENES = {2: "paper-circle-slow", 3: "spatial-cogiro"}


@pytest.fixture(scope="module", params=[2, 3], ids=["planar", "spatial"])
def run(request):
    scene = load_scene(SCENES[request.param])
    return simulate(scene.with_changes(solver=replace(scene.solver, end_time=0.3)))


def test_a_run_of_either_dimension_is_one_result_type_with_its_space_as_data(run):
    space = PLANE if run.dimension == 2 else SPACE
    assert type(run) is Result and run.space is space
    n = len(run.time)
    assert run.pose.shape == run.reference.shape == (n, space.pose_size)
    assert run.position.shape == run.position_error.shape == (n, space.position_size)
    assert all(nodes.shape[0] == n and nodes.shape[2] == space.dimension for nodes in run.nodes)
    np.testing.assert_array_equal(run.position_error, (run.pose - run.reference)[:, :space.position_size])


def test_save_and_load_give_back_every_array_and_the_dimension(run, tmp_path):
    written = run.save(tmp_path / "run", after=0.1)
    loaded = Result.load(written["npz"].parent)
    assert (loaded.scene_name, loaded.controller, loaded.dimension, loaded.status, loaded.steps) == (
        run.scene_name, run.controller, run.dimension, run.status, run.steps)
    for name in ("time", "pose", "reference", "paid_out", "velocity", "pulley_penetration", "winch_reservoir"):
        mine, theirs = getattr(run, name), getattr(loaded, name)
        assert (mine is None) == (theirs is None), name
        if mine is not None:
            np.testing.assert_array_equal(theirs, mine, err_msg=name)
    for mine, theirs in zip(run.nodes + run.tensions, loaded.nodes + loaded.tensions):
        np.testing.assert_array_equal(theirs, mine)
    # the same figures from the file as from the run (the wall time lives in timing.json)
    summary = {k: v for k, v in run.summary(0.1).items() if k not in ("wall_time_s", "real_time_factor")}
    assert {k: loaded.summary(0.1)[k] for k in summary} == summary
    written_summary = json.loads(written["summary"].read_text())
    assert written_summary["after_start_up"]["errors_measured_after_s"] == 0.1
    header = written["csv"].read_text().splitlines()[0]
    assert header.count("_ref_") == run.space.pose_size  # one reference column per pose entry


def test_the_summary_names_its_figures_from_the_space_labels(run):
    space, summary = run.space, run.summary(0.1)
    mask = run.time >= 0.1
    error = run.position_error[mask]
    for k, axis in enumerate(space.position_labels):
        assert summary[f"max_abs_error_{axis}_m"] == np.abs(error[:, k]).max()
    assert summary["min_error_z_m"] == error[:, space.vertical].min()
    assert summary["max_error_z_m"] == error[:, space.vertical].max()
    assert summary["max_position_error_m"] == np.linalg.norm(error, axis=1).max()
    assert summary["max_abs_rotation_deg"] == pytest.approx(
        np.degrees(np.linalg.norm(run.pose[mask, space.position_size:], axis=1)).max(), rel=1e-12)
    # every error figure is measured after the window; planar summaries keep their committed layout
    assert set(run.error_figures) <= set(summary)
    assert all(key not in summary for key in LEFT_OUT[space])
    assert ("dimension" in summary) == (space is SPACE) and ("max_rotation_error_deg" in summary) == (space is SPACE)
    assert summary["errors_measured_after_s"] == 0.1


def test_the_safety_figures_start_after_the_initial_condition(run):
    """Issue 23 follow-up: a planar run starts from straight unstretched cables whose every element
    carries nothing at t = 0 (0 N, round-off of 1e-30 N); the lowest tension and the slack time are the
    run's, after it (measured 16.2 N on the slow circle's first second)."""
    summary = run.summary()
    later = run.time > 0.0
    lowest = [float(t[later].min()) for t in run.tensions]
    assert summary["min_tension_per_cable_N"] == lowest and summary["min_element_tension_N"] == min(lowest)
    if run.space is PLANE:  # the paper circle's cables carry nothing at t = 0, and something at once after
        assert all(t[0].min() == 0.0 and t[0].max() < 1e-20 for t in run.tensions)
        assert min(lowest) > 0.0 and summary["slack_time_per_cable_s"] == [0.0, 0.0]
    assert not summary["elements_pushed"] and summary["warnings"] == []


def test_compression_in_the_initial_state_is_still_flagged_and_said_to_be_there():
    """Only the lowest tension and the slack time skip t = 0: an element that pushes in the state a run
    starts from (a spatial start over bent chains does, issue 23.1) is reported, and the warning says
    it is the initial state."""
    times = np.array([0.0, 0.1, 0.2])
    tensions = [np.array([[-3.0, 2.0], [1.0, 2.0], [1.5, 2.5]]), np.array([[4.0], [5.0], [6.0]])]
    figures = safety_figures(times, tensions)
    assert figures["elements_pushed"] and figures["min_element_tension_N"] == 1.0
    assert figures["min_tension_per_cable_N"] == [1.0, 5.0] and figures["slack_time_per_cable_s"] == [0.0, 0.0]
    (warning,) = figures["warnings"]
    assert "lowest tension -3 N, cable 1 at t = 0.0000 s" in warning and "in the initial state, at t = 0 only" in warning
    tensions[0][2, 0] = -1.0  # pushing later too: the initial state is named, not "only"
    (warning,) = safety_figures(times, tensions)["warnings"]
    assert "in the initial state, at t = 0, where" in warning and "t = 0 only" not in warning


def test_a_spatial_start_with_a_compressed_element_is_flagged():
    """The coarse four-cable robot held at its catenary start with spring elements: the lowest elements of
    cables 2 and 4 are compressed at t = 0 (-0.1 N and -4.86 N measured, tests/test_spatial_run.py). The run is
    flagged, and the warning says the compression is in the initial state."""
    from test_spatial_run import pushing_four_cable

    result = simulate(pushing_four_cable(end_time=0.2))
    summary = result.summary()
    assert summary["elements_pushed"] and min(t[0].min() for t in result.tensions) < -1.0
    (warning,) = summary["warnings"]
    assert "cable 4 at t = 0.0000 s; first push at t = 0.0000 s; in the initial state, at t = 0" in warning
    later = result.time > 0.0
    assert summary["min_element_tension_N"] == min(t[later].min() for t in result.tensions)


class _RateSpy:
    """Ideal IK that records the winch rates it is given and the rates it commands."""

    name, uses_pose, uses_tension = "spy", False, False

    def __init__(self):
        from controllers.ideal_ik import IdealIKController

        self.inner, self.seen, self.sent = IdealIKController(), [], []

    def reset(self, scene, initial_paid_out):
        self.inner.reset(scene, initial_paid_out)

    def command(self, measurement):
        self.seen.append(np.array(measurement.paid_out_rate))
        command = self.inner.command(measurement)
        self.sent.append(np.array(command.paid_out_rate))
        return command


@pytest.mark.parametrize("dimension", [2, 3], ids=["planar", "spatial"])
def test_the_controller_is_given_the_winches_rate_in_both_dimensions(dimension):
    """Issue 24: Measurement.paid_out_rate is the winches' rate on spatial runs too (it was zero there):
    the rate of the last command (the ideal IK's commands start where the winches are, so the run's
    smooth start passes them on unchanged), zero before the first."""
    scene = load_scene(SCENES[dimension])
    spy = _RateSpy()
    simulate(scene.with_changes(solver=replace(scene.solver, end_time=0.3)), spy)
    # seen[0]: the smooth start's command at reset; seen[1]: the run's first step, before any command
    assert not spy.seen[1].any() and len(spy.seen) > 20
    for k in range(2, len(spy.seen)):
        np.testing.assert_array_equal(spy.seen[k], spy.sent[k - 1])
    assert max(np.abs(rate).max() for rate in spy.seen) > 1e-3  # the circle's winches move [m/s]
