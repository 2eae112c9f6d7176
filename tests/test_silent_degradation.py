"""Nothing degrades silently: coarse output warns, scene files must say what they mean,
and a failure's hint follows its cause (issues 11 and 12)."""

import subprocess
import sys
import warnings
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import CoarseOutputWarning, SceneError, SolverFailure
from cdpr_exu.scenes.scene import load_scene, shipped_scenes
from cdpr_exu.run.simulate import simulate
from cdpr_exu.run.solver import likely_cause

PAPER = load_scene("paper-circle")


def test_a_step_longer_than_the_output_period_warns_with_the_sample_count():
    with pytest.warns(CoarseOutputWarning, match=r"solver.step_size = 0.5 s .* \(21 samples over 10.0 s\)"):
        replace(PAPER.solver, step_size=0.5)


def test_the_cli_prints_the_coarse_output_warning_as_one_line():
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "run", "paper-circle", "--step-size", "0.5",
                           "--end-time", "1", "-q"], capture_output=True, text=True, timeout=300)
    assert "cdpr: warning: solver.step_size = 0.5 s" in done.stderr and "warnings.warn" not in done.stderr


def test_shipped_scenes_load_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in shipped_scenes():
            load_scene(name)


def test_an_empty_scene_file_is_refused_naming_the_missing_tables(tmp_path):
    path = tmp_path / "empty.toml"
    path.write_text("")
    with pytest.raises(SceneError, match=r"lacks pulleys, platform, trajectory"):
        load_scene(path)


def test_a_point_to_point_without_end_is_refused_naming_trajectory_end(tmp_path):
    path = tmp_path / "p2p.toml"  # the paper scene with its trajectory replaced
    source = (tmp_path / "paper.toml")
    from cdpr_exu.scenes.scene import save_scene

    save_scene(PAPER, source)
    body = source.read_text().split("[trajectory]")[0]
    path.write_text(body + '[trajectory]\nkind = "point_to_point"\nstart = [0.0, -2.0, 0.0]\n')
    with pytest.raises(SceneError, match=r"trajectory\.end is required"):
        load_scene(path)


@pytest.mark.parametrize("failure, expected", [
    ("element 3 of cable 1 is strained by +6.2 % at t = 1.0 s", "too soft"),
    ("element 3 of cable 1 cuts 140 mm deep into pulley 1 at t = 1.0 s", "slipped into the pulley"),
    ("the platform rose above the pulleys at t = 0.9 s", "thrown upwards"),
    ("the coordinates are no longer finite at t = 0.5 s", "diverged"),
])
def test_the_hint_follows_the_cause_the_monitor_found(failure, expected):
    hint = likely_cause(PAPER, failure, failure_time=1.0)
    assert expected in hint and "a sudden jump of the winch command" not in hint


def test_a_run_that_fails_at_t_0_says_what_in_the_scene_makes_the_first_step_fail():
    scene = PAPER.with_changes(solver=replace(PAPER.solver, end_time=0.2, max_newton_iterations=1))
    with pytest.raises(SolverFailure, match=r"at t = 0 the first step failed: solver.max_newton_iterations = 1"):
        simulate(scene)


def test_a_result_that_needs_cables_to_push_is_flagged_and_tension_only_cables_are_not():
    """The paper's spring elements push at the start-up (lowest tension -6.5 N measured);
    tension-only elements never do. Every summary gives each cable's lowest tension and
    the time any of its elements carried no tension."""
    from cdpr_exu.scenes.scene import Effects

    short = PAPER.with_changes(solver=replace(PAPER.solver, end_time=0.5))
    result = simulate(short.with_changes(effects=Effects.from_preset("paper")))
    spring = result.summary()
    assert spring["elements_pushed"] and spring["min_element_tension_N"] < 0
    assert any("pushed" in warning for warning in spring["warnings"])
    # Issue 23.1: the safety figures cover the whole run whatever the error window: measured
    # from 1 s on, this 0.5 s run has no error figures, but its pushing is reported all the same.
    windowed = result.summary(after=1.0)
    assert windowed["max_position_error_m"] is None
    for key in ("elements_pushed", "min_element_tension_N", "min_tension_per_cable_N", "slack_time_per_cable_s",
                "warnings"):
        assert windowed[key] == spring[key], key
    assert min(spring["min_tension_per_cable_N"]) == spring["min_element_tension_N"]
    assert all(0.0 < t <= 0.5 for t in spring["slack_time_per_cable_s"])
    tension_only = simulate(short).summary()  # the default "full" preset: tension-only elements
    assert not tension_only["elements_pushed"] and tension_only["min_element_tension_N"] >= 0.0


def test_a_real_run_thrown_above_the_pulleys_gets_the_hint_for_that_cause():
    """Issue 12.4 on the real solver: the bending-free paper circle at spectral radius 0.5 is
    thrown off at the start-up (the README's claim); the monitor stops it with the platform
    above the pulleys, and the hint speaks of that, not of the generic winch jump."""
    from cdpr_exu.scenes.scene import Effects

    scene = PAPER.with_changes(effects=Effects.from_preset("catenary", slack=False),
                               solver=replace(PAPER.solver, spectral_radius=0.5, end_time=1.5))
    with pytest.raises(SolverFailure, match="rose above the pulleys") as failure:
        simulate(scene)
    message = str(failure.value)
    hint = message.split("Likely cause:")[1]
    assert "thrown upwards" in hint and "a sudden jump of the winch command" not in hint
    assert 0.0 < failure.value.time < 1.5 and len(failure.value.partial_result.time) > 1


def test_a_scene_file_whose_step_is_longer_than_its_output_period_warns_once(tmp_path):
    """Issue 23.10c: `cdpr run` loaded a planar scene file twice (once to tell planar from
    spatial, once more to apply --end-time / --step-size), so the file's coarse-output
    warning was printed twice."""
    from cdpr_exu.scenes.scene import save_scene

    path = tmp_path / "coarse.toml"
    save_scene(PAPER.with_changes(solver=replace(PAPER.solver, end_time=0.04, step_size=0.02, output_period=0.02)), path)
    path.write_text(path.read_text().replace("output_period = 0.02", "output_period = 0.01"))
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "run", str(path), "--end-time", "0.04", "-q",
                           "--no-error-estimate"], capture_output=True, text=True, timeout=300)
    assert done.stderr.count("cdpr: warning: solver.step_size = 0.02 s") == 1, done.stderr


def test_a_platform_above_its_highest_exit_is_flagged_with_the_time_and_height():
    """Issue 23.1: the safety figures both summaries share (results.result.safety_figures) flag a
    platform above its highest exit (planar: pulley centre; spatial: exit point or swivel
    inlet), where every cable pulls it down, as they flag elements that push."""
    from cdpr_exu.results.result import safety_figures

    times = np.array([0.0, 0.1, 0.2, 0.3])
    tensions = [np.array([[5.0, 4.0], [3.0, 1.0], [0.0, -2.0], [1.0, 2.0]])]
    figures = safety_figures(times, tensions, heights=np.array([-1.0, -0.2, 0.05, 0.3]), highest_exit=0.0)
    assert figures["platform_above_exits"] and figures["elements_pushed"]
    assert figures["min_element_tension_N"] == -2.0 and figures["slack_time_per_cable_s"] == [pytest.approx(0.1)]
    pushed, above = figures["warnings"]
    assert "lowest tension -2 N, cable 1 at t = 0.2000 s; first push at t = 0.2000 s" in pushed
    assert "above its highest exit (z = 0 m) at t = 0.2000 s, up to z = 0.3 m" in above
    level = safety_figures(times, tensions, heights=np.full(4, -0.5), highest_exit=0.0)
    assert level["platform_above_exits"] is False and len(level["warnings"]) == 1
    assert safety_figures(times, tensions)["platform_above_exits"] is None  # no geometry: unknown, not "no"


def test_cdpr_run_says_once_that_a_completed_run_pushed(tmp_path):
    """Issue 23.1 on the console: a completed run whose recorded tensions push (the paper's spring
    elements at the start-up, -6.5 N measured) is not reported as a clean "completed": one
    UnphysicalResultWarning line, and the status says why."""
    from cdpr_exu.scenes.scene import Effects, save_scene

    path = tmp_path / "spring.toml"
    save_scene(PAPER.with_changes(effects=Effects.from_preset("paper"),
                                  solver=replace(PAPER.solver, end_time=0.5)), path)
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "run", str(path), "--no-error-estimate"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    warnings_ = [line for line in done.stderr.splitlines() if line.startswith("cdpr: warning:")]
    assert len(warnings_) == 1 and "paper-circle under ideal_ik: elements pushed" in warnings_[0], done.stderr
    assert "completed (cables pushed: see the warnings)" in done.stdout
