"""Tension limits t_min, t_max per cable (issue 13, item 2): refused references and reported violations."""

import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.studies.comparison import markdown_table
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.output import json_text
from cdpr_exu.scenes.scene import CableSpec, load_scene, save_scene
from cdpr_exu.run.simulate import simulate
from cdpr_exu.statics.workspace import check_reference

PAPER = load_scene("paper-circle")


def with_limits(scene, min_tension=None, max_tension=None, **solver):
    cables = tuple(replace(c, min_tension=min_tension, max_tension=max_tension) for c in scene.cables)
    return scene.with_changes(cables=cables, solver=replace(scene.solver, **solver))


@pytest.mark.parametrize("kwargs, field", [
    (dict(min_tension=-1.0), "cable.min_tension"),
    (dict(max_tension=float("nan")), "cable.max_tension"),
    (dict(min_tension=50.0, max_tension=40.0), "cable.min_tension"),
])
def test_bad_tension_limits_are_refused_naming_the_field(kwargs, field):
    with pytest.raises(SceneError, match=field):
        CableSpec(**kwargs)


def test_a_scene_keeps_its_tension_limits_through_toml(tmp_path):
    scene = with_limits(PAPER, 2.0, 300.0)
    again = load_scene(save_scene(scene, tmp_path / "limits.toml"))
    assert again.tension_limits == pytest.approx(np.array([[2.0, 300.0], [2.0, 300.0]]))
    assert PAPER.tension_limits is None  # no limits: no key in the file, nothing checked


def test_a_reference_the_limits_cannot_hold_is_refused_before_the_run_naming_the_cables():
    # At t = 0 the circle's bottom needs M (a + g) = 2.5 kg (0.9 + 9.8) m/s^2 = 26.75 N up,
    # 16.2 N in each cable (symmetric): a 15 N limit cannot hold it, a 20 N limit can.
    check_reference(with_limits(PAPER, max_tension=20.0))
    with pytest.raises(UnreachableError, match=r"t = 0\.000 s.*cables\[0\]\.max_tension = 15 N") as refused:
        check_reference(with_limits(PAPER, max_tension=15.0))
    assert "16.2 N" in str(refused.value)


def test_cdpr_run_refuses_such_a_reference_with_exit_code_2(tmp_path):
    path = save_scene(with_limits(PAPER, max_tension=15.0), tmp_path / "tight.toml")
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "run", str(path), "--no-error-estimate"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and "max_tension" in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_run_reports_each_limit_crossed_with_its_time_extreme_and_duration():
    result = simulate(with_limits(PAPER, 5.0, 40.0, end_time=1.5))
    summary = result.summary()
    violations = {(v["cable"], v["limit"]): v for v in summary["tension_limit_violations"]}
    for i, tensions in enumerate(result.tensions):
        low, high = tensions.min(axis=1), tensions.max(axis=1)
        widths = np.diff(result.time, append=result.time[-1])
        for name, crossed, extreme in (("min_tension", low < 5.0, low.min()), ("max_tension", high > 40.0, high.max())):
            if not crossed.any():
                assert (i + 1, name) not in violations
                continue
            # the report is the recorded series itself: same first sample, extreme and time beyond
            v = violations[(i + 1, name)]
            assert v["first_time_s"] == result.time[np.argmax(crossed)]
            assert v["extreme_N"] == pytest.approx(extreme, rel=1e-12)
            assert v["duration_s"] == pytest.approx(widths[crossed].sum(), rel=1e-12)
    assert violations, "the start-up transient of the paper circle crosses 5-40 N (measured -6.5 and 249 N)"
    json.loads(json_text(summary))  # strict JSON: limits and violations have no NaN or inf


def test_limits_that_are_never_crossed_report_an_empty_list_and_no_limits_report_nothing():
    limited = simulate(with_limits(PAPER, None, 1.0e4, end_time=0.5)).summary()
    assert limited["tension_limit_violations"] == [] and limited["tension_limits_N"] == [[None, 1.0e4]] * 2
    assert "tension_limit_violations" not in simulate(PAPER.with_changes(
        solver=replace(PAPER.solver, end_time=0.2))).summary()


def test_the_comparison_table_has_a_violations_column_only_for_scenes_with_limits():
    plain = {"ideal_ik": {"max_position_error_m": 0.01, "status": "completed"}}
    limited = {"ideal_ik": {**plain["ideal_ik"], "tension_limit_violation_count": 3}}
    assert "violations" not in markdown_table(plain)
    assert "tension limit violations" in markdown_table(limited) and "| 3 |" in markdown_table(limited)
