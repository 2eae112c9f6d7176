"""Strict output files: JSON without NaN, empty CSV cells, stable archives, usable folders."""

import json
import math
import zipfile

import numpy as np
import pytest

from cdpr_exu.core.errors import OutputError
from cdpr_exu.core.output import check_output_folder, csv_cell, fixed, json_text, split_timing, write_npz


def _strict_loads(text):
    """json.loads that refuses the non-standard NaN/Infinity tokens, as strict parsers do."""
    def refuse(token):
        raise ValueError(f"non-standard JSON token {token}")
    return json.loads(text, parse_constant=refuse)


def test_json_text_writes_null_for_nan_and_infinity_at_any_depth():
    value = {"a": math.nan, "b": [1.0, math.inf, {"c": -math.inf}], "d": np.float64("nan"), "e": np.arange(2)}
    parsed = _strict_loads(json_text(value))
    assert parsed == {"a": None, "b": [1.0, None, {"c": None}], "d": None, "e": [0, 1]}


def test_csv_cell_is_empty_for_not_applicable_and_round_trips_numbers():
    assert csv_cell(None) == "" and csv_cell(math.nan) == "" and csv_cell(np.float32("nan")) == ""
    assert float(csv_cell(0.1 + 0.2)) == pytest.approx(0.3, rel=1e-9)  # 9 significant digits kept


@pytest.mark.parametrize("value", [-0.0, -0.001, -0.004999])
def test_fixed_never_prints_negative_zero(value):
    assert fixed(value, 2) == "0.00"


def test_fixed_keeps_the_sign_of_values_that_show():
    assert fixed(-0.006, 2) == "-0.01" and fixed(1.234, 1) == "1.2"


def test_split_timing_puts_wall_clock_figures_apart():
    stable, timing = split_timing({"wall_time_s": 1.0, "date": "x", "steps": 3, "real_time_factor": 2.0})
    assert stable == {"steps": 3} and set(timing) == {"wall_time_s", "date", "real_time_factor"}


def test_npz_of_the_same_data_is_byte_identical_and_loads(tmp_path):
    data = {"time": np.linspace(0, 1, 11), "info": np.array('{"a": 1}')}
    first, second = tmp_path / "a.npz", tmp_path / "b.npz"
    write_npz(first, **data)
    write_npz(second, **data)
    assert first.read_bytes() == second.read_bytes()
    with np.load(first) as loaded:
        np.testing.assert_array_equal(loaded["time"], data["time"])
        assert str(loaded["info"]) == '{"a": 1}'
    assert all(info.date_time == (2020, 1, 1, 0, 0, 0) for info in zipfile.ZipFile(first).infolist())


def test_output_folder_that_is_a_file_is_refused_with_the_option_named(tmp_path):
    existing = tmp_path / "taken"
    existing.write_text("x")
    with pytest.raises(OutputError, match=r"--out .*taken: is an existing file"):
        check_output_folder(existing)
    with pytest.raises(OutputError, match=r"taken is a file"):
        check_output_folder(existing / "inside")


def test_output_folder_is_created_with_its_parents(tmp_path):
    folder = check_output_folder(tmp_path / "a" / "b")
    assert folder.is_dir()


# --------------------------------------------------------------------------- folders of earlier runs (issue 23.15)


def test_a_command_clears_only_the_files_it_writes(tmp_path):
    """A run clears the files a run writes, the figures and the animation of the run it replaces
    included; what another tool (variants.md) or the user (notes.txt) put there stays, and so do
    folders."""
    from cdpr_exu.core.output import clear_outputs

    owned = ["scene.toml", "result.npz", "pose.csv", "summary.json", "timing.json", "solution.sol",
             "snapshots.png", "overview.png", "animation.gif"]
    kept = ["variants.md", "variants.json", "notes.txt", "pose_ideal_ik.csv"]
    for name in owned + kept:
        (tmp_path / name).write_text("old")
    (tmp_path / "frames").mkdir()
    removed = clear_outputs(tmp_path, "run")
    assert sorted(p.name for p in removed) == sorted(owned)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(kept + ["frames"])


def test_a_comparison_clears_the_tables_of_controllers_it_does_not_run_again(tmp_path):
    from cdpr_exu.core.output import clear_outputs

    for name in ("comparison.md", "pose_ilc.csv", "overview_tension_aware.png", "notes.md"):
        (tmp_path / name).write_text("old")
    clear_outputs(tmp_path, "compare")
    assert [p.name for p in tmp_path.iterdir()] == ["notes.md"]


@pytest.mark.parametrize("command, marker, other", [("run", "comparison.md", "compare"),
                                                    ("compare", "result.npz", "run"),
                                                    ("study sweep", "solution.sol", "run"),
                                                    ("static", "study.json", "study sweep")])
def test_a_folder_holding_another_commands_output_is_refused_naming_it(tmp_path, command, marker, other):
    """Two commands' files side by side would mix (a compare's scene.toml beside a run's
    solution.sol, which `cdpr view` would replay with it): refused, naming --out, the other
    command and its file, and nothing is touched."""
    (tmp_path / marker).write_text("keep me")
    (tmp_path / "summary.json").write_text("keep me too")
    with pytest.raises(OutputError, match=rf"--out .*holds the output of `cdpr {other}` \({marker}\)"):
        check_output_folder(tmp_path, command=command)
    assert (tmp_path / marker).read_text() == "keep me" and (tmp_path / "summary.json").read_text() == "keep me too"


def test_a_folder_of_the_same_commands_earlier_output_is_accepted(tmp_path):
    for name in ("result.npz", "solution.sol", "summary.json", "variants.md"):
        (tmp_path / name).write_text("old")
    assert check_output_folder(tmp_path, command="run") == tmp_path


def test_split_timing_finds_wall_clock_figures_at_any_depth_and_keeps_what_is_asked():
    """Issue 23.18: a comparison's per-controller and a study's per-row wall times sat in the tracked
    JSON because only top-level keys were split off."""
    summary = {"controllers": {"a": {"wall_time_s": 1.0, "max": 2.0}, "b": {"max": 3.0}},
               "rows": [{"real_time_factor": 5.0, "n": 1}, {"n": 2}], "date": "d"}
    stable, timing = split_timing(summary)
    assert stable == {"controllers": {"a": {"max": 2.0}, "b": {"max": 3.0}}, "rows": [{"n": 1}, {"n": 2}]}
    assert timing == {"controllers": {"a": {"wall_time_s": 1.0}}, "rows": [{"real_time_factor": 5.0}, {}], "date": "d"}
    stable, timing = split_timing({"rows": [{"cpu_time_s": 1.0}], "date": "d"}, keep=("cpu_time_s",))
    assert stable == {"rows": [{"cpu_time_s": 1.0}]} and timing == {"date": "d"}
