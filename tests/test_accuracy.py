"""Tests of the accuracy-against-cost study (cdpr_exu.studies.accuracy).

The ``--quick`` study runs on the real solver through the ``cdpr`` command (1.5 s of
the paper circle, 10 runs on two worker processes, about 20 s); the error measures
and the tables are checked on small synthetic series.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import zipfile

import numpy as np
import pytest

from cdpr_exu.studies.accuracy import (ACCURACY_FILES, FULL_GRID, QUICK_GRID, Configuration, cheapest_meeting, compare,
                               pareto_front)
from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.output import ZIP_DATE
from cdpr_exu.space import SPACE


@pytest.fixture(scope="module")
def quick_study(tmp_path_factory):
    """``cdpr study accuracy paper-circle --quick`` on two workers; its output folder."""
    out = tmp_path_factory.mktemp("accuracy")
    command = ["cdpr", "study", "accuracy", "paper-circle", "--out", str(out), "--quick", "--workers", "2", "--quiet"]
    completed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    return out


def _rows(out):
    with open(out / ACCURACY_FILES["csv"], newline="") as handle:
        return list(csv.DictReader(handle))


# --------------------------------------------------------------------------- real runs


@pytest.mark.slow
def test_quick_study_writes_its_files(quick_study):
    for name in ACCURACY_FILES.values():
        assert (quick_study / name).is_file(), name
    assert len(_rows(quick_study)) == len(QUICK_GRID.configurations())
    tables = (quick_study / ACCURACY_FILES["tables"]).read_text()
    assert "Cheapest configuration meeting each tolerance" in tables
    assert (quick_study / ACCURACY_FILES["pareto"]).stat().st_size > 10_000
    with zipfile.ZipFile(quick_study / ACCURACY_FILES["reference"]) as archive:  # same data, same bytes
        assert {info.date_time for info in archive.infolist()} == {ZIP_DATE}
    assert "date" not in json.loads((quick_study / ACCURACY_FILES["json"]).read_text())
    assert "date" in json.loads((quick_study / "timing.json").read_text())  # the date lives apart


@pytest.mark.slow
def test_quick_study_reference_is_the_finest_full_run(quick_study):
    rows = _rows(quick_study)
    reference = [r for r in rows if r["is_reference"] == "true"]
    assert len(reference) == 1
    reference = reference[0]
    assert reference["model"] == "full"
    lumped = [r for r in rows if r["n_elements"]]
    assert int(reference["n_elements"]) == max(int(r["n_elements"]) for r in lumped)
    assert float(reference["step_size_s"]) == min(float(r["step_size_s"]) for r in rows)
    info = json.loads((quick_study / ACCURACY_FILES["json"]).read_text())
    assert info["reference"]["configuration"] == QUICK_GRID.reference.label


@pytest.mark.slow
def test_quick_study_errors_are_zero_for_the_reference_and_finite_elsewhere(quick_study):
    for row in _rows(quick_study):
        assert row["status"] == "completed", row["status"]
        errors = [float(row[name]) for name in ("position_error_max_m", "position_error_rms_m",
                                                "rotation_error_max_deg", "tension_error_rms_N")]
        if row["is_reference"] == "true":
            assert errors == [0.0, 0.0, 0.0, 0.0]
        else:
            assert all(math.isfinite(e) for e in errors)
            # 1.5 s of the circle: no model of the ladder leaves the reference's path by 10 cm
            assert 0.0 < float(row["position_error_max_m"]) < 0.1
            assert float(row["wall_time_s"]) > 0.0 and float(row["cpu_time_s"]) > 0.0


@pytest.mark.slow
def test_quick_study_finer_steps_of_the_reference_model_are_closer_to_it(quick_study):
    rows = {(r["model"], r["n_elements"], float(r["step_size_s"])): r for r in _rows(quick_study)}
    coarse = float(rows[("full", "12", 5e-3)]["position_error_max_m"])
    finer_elements = float(rows[("full", "20", 5e-3)]["position_error_max_m"])
    assert finer_elements < coarse


# --------------------------------------------------------------------------- pure functions


def _series(times, x, tension=10.0):
    pose = np.column_stack([x, np.full_like(times, -2.0), np.zeros_like(times)])
    return {"time": times, "pose": pose, "end_tensions": np.full((len(times), 2), tension),
            "speed": np.zeros_like(times)}


def test_compare_measures_the_path_after_the_start_up_on_the_reference_times():
    reference = _series(np.linspace(0.0, 2.0, 201), np.zeros(201))
    times = np.linspace(0.0, 2.0, 81)  # a coarser run, interpolated onto the reference's times
    offset = np.where(times < 1.0, 0.5, 0.002)  # a big error before 1 s does not count
    errors = compare(_series(times, offset, tension=11.0), reference, "path", after=1.0)
    assert errors["position_error_max_m"] == pytest.approx(0.002)
    assert errors["position_error_rms_m"] == pytest.approx(0.002)
    assert errors["tension_error_rms_N"] == pytest.approx(1.0)


def test_compare_final_uses_the_last_samples_only():
    reference = _series(np.linspace(0.0, 8.0, 9), np.zeros(9))
    errors = compare(_series(np.linspace(0.0, 8.0, 9), np.r_[np.ones(8), 0.003]), reference, "final")
    assert errors["position_error_max_m"] == pytest.approx(0.003)


def test_compare_gives_nan_for_a_run_that_stopped_early():
    reference = _series(np.linspace(0.0, 2.0, 201), np.zeros(201))
    errors = compare(_series(np.linspace(0.0, 1.5, 151), np.zeros(151)), reference, "path", after=1.0)
    assert math.isnan(errors["position_error_max_m"])
    with pytest.raises(SceneError, match="comparison"):
        compare(reference, reference, "sideways")


def test_pareto_front_and_cheapest_configuration_per_tolerance():
    def row(model, wall, error, status="completed"):
        return {"model": model, "cpu_time_s": wall, "position_error_max_m": error, "status": status,
                "is_reference": False}

    rows = [row("a", 1.0, 0.05), row("b", 2.0, 0.02), row("c", 3.0, 0.03), row("d", 4.0, 0.0005),
            row("e", 0.5, 0.1, status="failed: stopped"), {**row("ref", 9.0, 0.0), "is_reference": True}]
    assert [r["model"] for r in pareto_front(rows)] == ["a", "b", "d"]
    assert cheapest_meeting(rows, 1e-3)["model"] == "d"
    assert cheapest_meeting(rows, 0.025)["model"] == "b"
    assert cheapest_meeting(rows, 1e-4) is None  # the reference never counts


def test_full_grid_runs_every_preset_and_the_linear_bending_once_per_step_or_discretisation():
    configurations = FULL_GRID.configurations()
    assert configurations[0] == FULL_GRID.reference
    assert len(configurations) == len(set(configurations))
    models = {c.model for c in configurations}
    assert {"ideal", "elastic", "catenary", "full", "full, linear bending"} <= models
    ideal = [c for c in configurations if c.preset == "ideal"]
    assert all(c.n_elements is None for c in ideal)  # massless ropes: elements do not apply
    assert len(ideal) == len(FULL_GRID.step_sizes)
    assert Configuration("catenary", 8, 5e-4) in configurations  # refused by the builder: a result too


# --------------------------------------------------------------------------- spatial scenes (issue 15)


def _spatial_move_scene(tmp_path):
    """The shipped four-cable robot on a 1 s point-to-point move (15, -10, 5 cm) from its catenary
    rest pose, as a TOML file; its path is compared after the move (1 s)."""
    from dataclasses import replace

    from cdpr_exu.statics.statics import catenary_platform, solve_statics
    from cdpr_exu.scenes.scene import load_scene, save_scene
    from cdpr_exu.scenes.trajectories import PointToPointTrajectory
    from cdpr_exu.space import SPACE

    scene = load_scene("spatial-four-cable")
    rest = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    start = np.concatenate([rest.position, rest.rotation])
    end = start + np.array([0.15, -0.10, 0.05, 0.0, 0.0, 0.0])
    move = PointToPointTrajectory(tuple(start), tuple(end), duration=1.0, space=SPACE)
    scene = replace(scene, trajectory=move, solver=replace(scene.solver, output_period=0.01))
    return save_scene(scene, tmp_path / "four_cable_move.toml")


@pytest.mark.slow
def test_quick_spatial_study_writes_its_files_and_its_errors_fall_with_the_elements(tmp_path):
    """`cdpr study accuracy` on a spatial scene, --quick: the full model at 4 and 8 elements
    (1e-2 s) against 16 elements, 1.5 s. Measured: 1.22 mm and 0.207 deg at 4 elements,
    0.166 mm and 0.041 deg at 8 after the move; bound: the 8-element error below half
    the 4-element one, both above zero, rotations below 5 deg. Strict
    outputs: no NaN in the JSON, no "nan" in the CSV."""
    from cdpr_exu.studies.accuracy import SPATIAL_QUICK_GRID

    out = tmp_path / "study"
    command = ["cdpr", "study", "accuracy", str(_spatial_move_scene(tmp_path)), "--out", str(out), "--quick",
               "--workers", "2", "--quiet"]
    completed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    for name in ACCURACY_FILES.values():
        assert (out / name).is_file(), name
    rows = _rows(out)
    assert len(rows) == len(SPATIAL_QUICK_GRID.configurations()) == 3
    assert all(r["status"] == "completed" for r in rows)
    assert "nan" not in (out / ACCURACY_FILES["csv"]).read_text().lower()
    info = json.loads((out / ACCURACY_FILES["json"]).read_text(), parse_constant=lambda c: pytest.fail(c))
    assert info["reference"]["n_elements"] == 16
    error = {int(r["n_elements"]): float(r["position_error_max_m"]) for r in rows if r["is_reference"] == "false"}
    assert 0.0 < error[8] < 0.5 * error[4]
    assert all(0.0 <= float(r["rotation_error_max_deg"]) < 5.0 for r in rows)
    reference = [r for r in rows if r["is_reference"] == "true"][0]
    assert float(reference["position_error_max_m"]) == 0.0


def test_spatial_compare_measures_the_3d_path_and_the_rotation_angle():
    """Spatial poses (x, y, z, rotation vector): the error is the 3-D distance and the angle
    between the orientations (0.02 rad about z = 1.146 deg)."""
    times = np.linspace(0.0, 2.0, 21)
    pose = np.zeros((21, 6))
    run = {"time": times, "pose": pose + np.array([0.003, 0.004, 0.012, 0.0, 0.0, 0.02]),
           "end_tensions": np.zeros((21, 4)), "speed": np.zeros(21)}
    reference = {"time": times, "pose": pose, "end_tensions": np.zeros((21, 4)), "speed": np.zeros(21)}
    errors = compare(run, reference, "path", after=1.0, space=SPACE)
    assert errors["position_error_max_m"] == pytest.approx(0.013)
    assert errors["rotation_error_max_deg"] == pytest.approx(math.degrees(0.02))


def test_a_spatial_scene_without_a_trajectory_is_refused_before_any_run():
    from cdpr_exu.studies.accuracy import SPATIAL_QUICK_GRID, run_accuracy_study

    with pytest.raises(SceneError, match="no \\[trajectory\\]"):
        run_accuracy_study("spatial-four-cable", SPATIAL_QUICK_GRID, progress=False)


def test_spatial_grids_scale_their_elements_to_what_a_swivel_pulley_takes():
    """Point exits take any count: the spatial grids as they are. Over the swivel pulleys of
    spatial-four-cable-swivel (cables of 2.4 m on 0.1 m discs, elements <= 0.05 m) at least 48
    elements: the quick grid's 4, 8 and 16 become 48, 96 and 192, every one a valid scene."""
    from dataclasses import replace

    from cdpr_exu.scenes.scene import load_scene
    from cdpr_exu.studies.accuracy import SPATIAL_FULL_GRID, SPATIAL_QUICK_GRID, fewest_elements, grid_for

    assert grid_for(load_scene("spatial-ipanema"), quick=True) == SPATIAL_QUICK_GRID
    assert grid_for(load_scene("spatial-ipanema")) == SPATIAL_FULL_GRID
    swivel = load_scene("spatial-four-cable-swivel")
    assert fewest_elements(swivel) == 48
    quick = grid_for(swivel, quick=True)
    assert quick.n_elements == (48, 96) and quick.reference.n_elements == 192
    for configuration in quick.configurations():
        replace(swivel, cables=tuple(replace(c, n_elements=configuration.n_elements) for c in swivel.cables))
