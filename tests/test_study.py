"""Tests of parameter studies (cdpr_exu.studies.study): paths, grids, files, failures, Dask.

Real runs of the paper's circle, cut to 0.3 s so that the whole file stays well
under a minute on two cores. Wall times are never asserted; the physics is checked
for sanity instead (every run reaches its end time, errors finite and bounded).
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys

import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import load_scene, scene_from_dict
from cdpr_exu.studies.study import (FIGURES, Variation, apply_parameters, check_parameter_path, combinations,
                            parse_parameter, run_study)

#: Simulated time of every run here [s]: 150 steps of 2 ms, enough for the platform
#: to start moving along the circle.
END_TIME = 0.3

#: The 2 x 2 grid every study test runs. 10 elements (0.375 m, 1.5 pulley radii) is
#: about the coarsest the paper circle accepts: longer elements cut into the pulley as
#: chords of the wrap and are refused by the builder.
GRID = ["cables.n_elements=10,15", "platform.mass=1,2.5"]

#: Figures that do not depend on the machine's load (all but the timings).
DETERMINISTIC = [f for f in FIGURES if f not in ("wall_time_s", "real_time_factor")]


def _short_scene():
    scene = load_scene("paper-circle")
    data = scene.to_dict()
    data["solver"]["end_time"] = END_TIME
    return scene_from_dict(data)


def _read_csv(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def _same_numbers(rows_a, rows_b):
    """Rows of two studies agree in every deterministic figure to 1e-9 (relative)."""
    assert len(rows_a) == len(rows_b)
    for a, b in zip(rows_a, rows_b):
        assert a["status"] == b["status"]
        for name in DETERMINISTIC:
            # an empty CSV cell means "not applicable" (never the text "nan")
            x, y = (float(v) if v != "" else math.nan for v in (a[name], b[name]))
            if math.isnan(x):
                assert math.isnan(y), name
            else:
                assert y == pytest.approx(x, rel=1e-9, abs=1e-12), name


@pytest.fixture(scope="module")
def cli_grid(tmp_path_factory):
    """The 2 x 2 grid run through the ``cdpr`` command on a local process pool."""
    out = tmp_path_factory.mktemp("grid")
    command = ["cdpr", "study", "sweep", "paper-circle", "--end-time", str(END_TIME), "--out", str(out),
               "--workers", "2", "--quiet"]
    for parameter in GRID:
        command += ["--param", parameter]
    completed = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    return out


# --------------------------------------------------------------------------- parameters


def test_parameter_values_are_read_as_toml_scalars():
    assert parse_parameter("cables.n_elements=5,10,15") == Variation("cables.n_elements", (5, 10, 15))
    assert parse_parameter("platform.mass=1, 2.5,5").values == (1, 2.5, 5)
    assert parse_parameter("solver.step_size=1e-3,2e-3").values == (1e-3, 2e-3)
    assert parse_parameter("effects.bending=true,false").values == (True, False)
    assert parse_parameter("effects.preset=full,catenary").values == ("full", "catenary")
    assert parse_parameter('effects.preset="full","catenary"').values == ("full", "catenary")
    assert parse_parameter("cables[1].radius=0.004").path == "cables[1].radius"


@pytest.mark.parametrize("text", ["platform.mass", "platform.mass=", "platform.mass=[1,2]", "platform..mass=1",
                                  "cables[x].radius=1", "platform.mass=1,{a=1}"])
def test_malformed_parameter_raises_scene_error(text):
    with pytest.raises(SceneError):
        parse_parameter(text)


@pytest.mark.parametrize("path, named", [
    ("platform.weight", "'weight'"),
    ("cable.radius", "'cable'"),
    ("cables[2].radius", "2 entries"),
    ("platform.initial_pose", "names a list"),
    ("solver", "names a table"),
    ("platform.mass[0]", "not a list"),
])
def test_unknown_parameter_path_raises_scene_error_naming_it(path, named):
    data = load_scene("paper-circle").to_dict()
    with pytest.raises(SceneError, match="platform|cable|solver") as info:
        check_parameter_path(data, path)
    assert repr(path) in str(info.value) and named in str(info.value)


def test_unknown_parameter_path_is_refused_before_any_run():
    with pytest.raises(SceneError, match="'platform.weight'"):
        run_study(_short_scene(), ["platform.mass=1,2", "platform.weight=3"], progress=False)


def test_unknown_parameter_path_on_the_command_line_exits_with_its_name(tmp_path):
    completed = subprocess.run(["cdpr", "study", "sweep", "paper-circle", "--param", "platform.weight=1,2",
                                "--out", str(tmp_path / "x"), "--quiet"], capture_output=True, text=True,
                               timeout=120)
    assert completed.returncode == 2
    assert "platform.weight" in completed.stderr


def test_list_field_without_index_applies_to_every_cable_and_indexed_to_one():
    data = load_scene("paper-circle").to_dict()
    every = apply_parameters(data, [("cables.n_elements", 8)])
    assert [c["n_elements"] for c in every["cables"]] == [8, 8]
    one = apply_parameters(data, [("cables[1].radius", 0.004), ("platform.initial_pose[1]", -1.9)])
    assert [c["radius"] for c in one["cables"]] == [0.005, 0.004]
    assert one["platform"]["initial_pose"] == [0.0, -1.9, 0.0]
    assert data["cables"][1]["radius"] == 0.005  # the base data is left alone


def test_effects_preset_parameter_switches_every_flag_of_the_preset():
    data = load_scene("paper-circle").to_dict()
    catenary = scene_from_dict(apply_parameters(data, [("effects.preset", "catenary")])).effects
    assert catenary.preset == "catenary" and not catenary.bending and not catenary.bending_damping
    # Switching bending off alone also switches its damping off (it needs bending).
    no_bending = scene_from_dict(apply_parameters(data, [("effects.bending", False)])).effects
    assert not no_bending.bending and not no_bending.bending_damping and no_bending.pulley_contact


def test_grid_is_the_cartesian_product_and_zip_pairs_values():
    a, b = Variation("platform.mass", (1, 2)), Variation("cables.n_elements", (8, 10, 15))
    grid = combinations([a, b], "grid")
    assert len(grid) == 6 and grid[1] == (("platform.mass", 1), ("cables.n_elements", 10))
    zipped = combinations([a, Variation("cables.n_elements", (8, 15))], "zip")
    assert zipped == [(("platform.mass", 1), ("cables.n_elements", 8)), (("platform.mass", 2), ("cables.n_elements", 15))]
    with pytest.raises(SceneError, match="equal numbers"):
        combinations([a, b], "zip")


# --------------------------------------------------------------------------- real studies


@pytest.mark.slow
def test_cli_grid_writes_one_row_per_run_with_parameter_columns_first(cli_grid):
    rows = _read_csv(cli_grid / "study.csv")
    assert list(rows[0])[:4] == ["cables.n_elements", "platform.mass", "run", "status"]
    assert [(r["cables.n_elements"], r["platform.mass"]) for r in rows] == [
        ("10", "1"), ("10", "2.5"), ("15", "1"), ("15", "2.5")]
    for row in rows:
        assert row["status"] == "completed"
        assert float(row["simulated_time_s"]) == pytest.approx(END_TIME)
        assert int(row["steps"]) >= round(END_TIME / 2e-3)  # Exudyn's step counter may count the start
        # The platform starts on the circle and lags it by centimetres in 0.3 s;
        # 0.2 m (half the circle's radius) would mean the run went wrong.
        assert 0.0 < float(row["max_position_error_m"]) < 0.2
        assert float(row["rms_position_error_m"]) <= float(row["max_position_error_m"])
        assert float(row["max_pulley_penetration_m"]) < 1e-3  # contact stiffness 1e7 N/m: sub-mm
        assert "wall_time_s" not in row  # issue 23.18: wall-clock figures live in timing.json
    timing = json.loads((cli_grid / "timing.json").read_text())
    assert len(timing["rows"]) == 4 and all(r["wall_time_s"] > 0.0 for r in timing["rows"])
    data = json.loads((cli_grid / "study.json").read_text())
    assert data["variations"] == [{"path": "cables.n_elements", "values": [10, 15]},
                                  {"path": "platform.mass", "values": [1, 2.5]}]
    assert data["base_scene"]["solver"]["end_time"] == END_TIME and "exudyn" in data["versions"]
    assert len(data["rows"]) == 4
    assert "date" not in data and "date" in json.loads((cli_grid / "timing.json").read_text())  # kept apart
    assert load_scene(cli_grid / "base_scene.toml").to_dict() == data["base_scene"]
    for name in ("vs_cables_n_elements.png", "vs_platform_mass.png", "heatmap.png"):
        assert (cli_grid / name).stat().st_size > 10_000


@pytest.mark.slow
def test_invalid_and_failing_variations_are_recorded_and_the_others_run(tmp_path):
    # zip: a valid run, a negative mass (refused by the scene), one Newton iteration
    # per step (the solver fails at once), an unreachable circle (refused before the run).
    rows = run_study(_short_scene(), ["platform.mass=2.5,-1,2.5,2.5", "solver.max_newton_iterations=25,25,1,25",
                                      "trajectory.radius=0.4,0.4,0.4,1.5"],
                     mode="zip", out=tmp_path, progress=False, workers=2)
    status = [row["status"] for row in rows]
    assert status[0] == "completed"
    assert status[1].startswith("refused: platform.mass must be positive")
    assert status[2].startswith("failed: ")
    assert status[3].startswith("refused: ") and "cable 1" in status[3]
    assert math.isfinite(rows[0]["max_position_error_m"]) and math.isnan(rows[1]["max_position_error_m"])
    written = _read_csv(tmp_path / "study.csv")
    assert [r["status"] for r in written] == status
    assert (tmp_path / "vs_platform_mass.png").exists() and not (tmp_path / "heatmap.png").exists()


@pytest.mark.slow
def test_local_dask_cluster_gives_the_same_rows_as_the_process_pool(cli_grid, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    reference = _read_csv(cli_grid / "study.csv")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        with distributed.get_task_stream(client) as tasks:
            rows = run_study(_short_scene(), GRID, executor=client.get_executor(), progress=False)
        assert sum("run_variation" in task["key"] for task in tasks.data) == 4  # ran on the cluster
        _same_numbers(reference, rows)
        # The same grid through the command line, pointed at the cluster's scheduler.
        out = tmp_path / "dask"
        command = ["cdpr", "study", "sweep", "paper-circle", "--end-time", str(END_TIME), "--out", str(out),
                   "--scheduler", cluster.scheduler_address, "--quiet"]
        for parameter in GRID:
            command += ["--param", parameter]
        completed = subprocess.run(command, capture_output=True, text=True, timeout=300)
        assert completed.returncode == 0, completed.stderr
    _same_numbers(reference, _read_csv(out / "study.csv"))


def test_study_help_shows_examples():
    completed = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "study", "sweep", "--help"],
                               capture_output=True, text=True, timeout=60)
    assert completed.returncode == 0
    assert "examples:" in completed.stdout and "--scheduler" in completed.stdout
