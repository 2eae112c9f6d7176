"""Tests of cdpr_exu.studies.workspace_grid and `cdpr workspace`: the grid, its files, resuming, bad input."""

import csv
import json
from concurrent.futures import ThreadPoolExecutor

import pytest

from cdpr_exu.cli.main import main
from cdpr_exu.cli.workspace import EPILOG
from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.statics.feasibility import tension_bounds
from cdpr_exu.studies.workspace_grid import MAX_GRID_BYTES, make_grid, run_workspace

PAPER = load_scene("paper-circle")
COGIRO = load_scene("spatial-cogiro")


class CountingPool(ThreadPoolExecutor):
    """A one-thread pool that counts the positions it is given (the grid's tasks are lists of them)."""

    def __init__(self):
        super().__init__(1)
        self.checked = 0

    def submit(self, function, *args):
        self.checked += len(args[-1])
        return super().submit(function, *args)


def test_the_help_example_writes_the_grid_its_table_summary_and_figure(tmp_path, capsys):
    example = EPILOG.split("\n")[1].split()  # cdpr workspace paper-circle --grid ... --out out/ws
    assert example[:3] == ["cdpr", "workspace", "paper-circle"]
    out = tmp_path / "ws"
    assert main([*example[1:example.index("--out")], "--out", str(out), "--workers", "1"]) == 0
    assert "The catenary model keeps" in capsys.readouterr().out
    for name in ("workspace.csv", "summary.json", "summary.md", "slices.png", "scene.toml", "grid.json"):
        assert (out / name).is_file(), name
    text = (out / "workspace.csv").read_text()
    assert "nan" not in text.lower()
    rows = list(csv.DictReader(text.splitlines()))
    assert len(rows) == 13 * 13
    for row in rows:  # the tensions are given exactly where the model holds, empty where it does not
        assert (row["massless_tension_1_N"] != "") == (row["massless_status"] == "held")
        assert (row["catenary_sag_2_m"] != "") == (row["catenary_status"] == "held")
    summary = json.loads((out / "summary.json").read_text(), parse_constant=pytest.fail)
    assert summary["unit"] == "m^2" and summary["cell"] == pytest.approx(0.0625)
    held = summary["held_positions"]
    assert held["massless"] == sum(r["massless_status"] == "held" for r in rows) > held["catenary"] > 0
    assert summary["catenary_keeps"] == pytest.approx(summary["held_by_both"] / held["massless"])


def test_an_interrupted_grid_resumes_where_it_stopped(tmp_path):
    grid = make_grid(COGIRO, ["x=-4:4:5", "y=0", "z=1:3:3"])
    limits = tension_bounds(COGIRO, 100.0, 5000.0)
    first = run_workspace(COGIRO, grid, limits, tmp_path, executor=ThreadPoolExecutor(1), progress=False, chunk=4)
    lines = (tmp_path / "points.jsonl").read_text().splitlines()
    (tmp_path / "points.jsonl").write_text("\n".join(lines[:-5]) + "\n" + lines[-5][:20])  # 5 rows lost, 1 cut short
    pool = CountingPool()
    again = run_workspace(COGIRO, grid, limits, tmp_path, executor=pool, progress=False, chunk=4)
    assert pool.checked == 5 and again == first and len((tmp_path / "points.jsonl").read_text().splitlines()) == 15
    assert (tmp_path / "view3d.png").exists() is False  # two varied axes: slices only
    with pytest.raises(Exception, match="holds the rows of another grid"):
        run_workspace(COGIRO, make_grid(COGIRO, ["x=-4:4:3"]), limits, tmp_path, executor=pool, progress=False)


def test_a_spatial_grid_over_three_axes_and_two_orientations(tmp_path):
    """A position is held when it is held at every orientation: a yaw of 0.3 rad costs CoGiRo positions."""
    limits = tension_bounds(COGIRO, 100.0, 5000.0)
    axes = ["x=-6:6:4", "y=-4:4:3", "z=1:4:3"]
    one = run_workspace(COGIRO, make_grid(COGIRO, axes), limits, executor=ThreadPoolExecutor(1), progress=False)
    grid = make_grid(COGIRO, axes, [[0.0, 0.0, 0.0], [0.0, 0.0, 0.3]])
    both = run_workspace(COGIRO, grid, limits, tmp_path, executor=ThreadPoolExecutor(1), progress=False)
    assert len(both) == 2 * len(one) and (tmp_path / "view3d.png").is_file()
    summary = json.loads((tmp_path / "summary.json").read_text())
    single = sum(r["massless_status"] == "held" for r in one)
    assert summary["unit"] == "m^3" and summary["held_positions"]["massless"] < single


@pytest.mark.parametrize("arguments, field", [
    (["--grid", "x=1:0:5"], "grid x: '1:0:5' is empty"),
    (["--grid", "x=0:1:0"], "grid x: '0:1:0' is empty"),
    (["--grid", "x=nan:1:5"], "grid x: 'nan:1:5' must read START:STOP:COUNT"),
    (["--grid", "q=0:1:5"], "grid 'q=0:1:5': the axis must be one of x, z"),
    (["--grid", "x=0:1:5", "--grid", "x=0"], "grid x: given twice"),
    (["--grid", "x=-1:1:20000", "--grid", "z=-3:-1:20000"], "GiB allowed"),
    (["--grid", "x=-1:1:1000000000"], "GiB allowed"),  # refused before its values are made
    (["--grid", "x=0:1:5", "--orientation", "nan"], "orientation"),
    (["--grid", "x=0:1:5", "--orientation", "a"], "orientation 'a' must be numbers"),
])
def test_bad_input_is_refused_naming_the_field_and_nothing_is_written(tmp_path, capsys, arguments, field):
    out = tmp_path / "never"
    assert main(["workspace", "paper-circle", *arguments, "--min-tension", "1", "--max-tension", "100",
                 "--out", str(out)]) == 2
    assert field in capsys.readouterr().err and not out.exists()


def test_a_scene_without_tension_limits_is_refused_before_anything_is_written(tmp_path, capsys):
    assert main(["workspace", "paper-circle", "--grid", "x=0:1:3", "--out", str(tmp_path / "never")]) == 2
    assert "cables[0].min_tension and cables[0].max_tension must bound" in capsys.readouterr().err
    assert not (tmp_path / "never").exists()


def test_the_grid_estimates_its_memory_before_it_allocates():
    with pytest.raises(SceneError, match=r"need about \d+\.\d GiB"):
        make_grid(COGIRO, ["x=-7:7:1000", "y=-5:5:1000", "z=0:5:1000"])  # 1e9 positions: refused at once
    grid = make_grid(COGIRO, ["x=-7:7:100", "y=-5:5:100"])
    assert grid.size * 100 * 56 < MAX_GRID_BYTES and grid.values[2] == (2.265,)  # z stays at the start pose


@pytest.mark.slow
def test_a_local_dask_cluster_gives_the_rows_of_a_thread_pool():
    pytest.importorskip("dask.distributed")
    grid, limits = make_grid(PAPER, ["x=-1:1:3", "z=-3:-1:3"]), tension_bounds(PAPER, 1.0, 40.0)
    on_dask = run_workspace(PAPER, grid, limits, scheduler="local", workers=1, progress=False, chunk=4)
    assert on_dask == run_workspace(PAPER, grid, limits, executor=ThreadPoolExecutor(1), progress=False)
