"""The ``cdpr`` command as a user runs it (subprocess), and the files it writes."""

import json
import re
import subprocess
import sys

import numpy as np
import pytest

from cdpr_exu.core.output import TIMING_KEYS
from cdpr_exu.results.result import Result


def _cdpr(*args, check=True):
    return subprocess.run([sys.executable, "-m", "cdpr_exu.cli", *args], capture_output=True, text=True,
                          check=check, timeout=600)


def test_run_writes_result_summary_solution_and_figures(tmp_path):
    out = tmp_path / "run"
    done = _cdpr("run", "paper-circle", "--end-time", "0.3", "--out", str(out))
    assert "max |error x|" in done.stdout and "written to" in done.stdout
    summary = json.loads((out / "summary.json").read_text())
    for key in ("max_abs_error_x_m", "max_abs_error_z_m", "max_abs_rotation_deg", "min_element_tension_N",
                "max_pulley_penetration_m", "simulated_time_s", "steps", "versions"):
        assert key in summary, key
    timing = json.loads((out / "timing.json").read_text())  # what changes from run to run lives apart
    assert {"wall_time_s", "real_time_factor", "date"} <= set(timing) <= set(TIMING_KEYS) and timing["wall_time_s"] > 0
    # issue 25: the solve's CPU time beside its wall time, printed too (the speed checks read it)
    assert timing["cpu_time_s"] > 0 and "cpu_time_s" not in summary and "simulated / wall / CPU" in done.stdout
    assert summary["simulated_time_s"] == pytest.approx(0.3)
    assert summary["error_convention"] == "actual - reference"
    for name in ("result.npz", "pose.csv", "solution.sol", "scene.toml", "overview.png", "snapshots.png",
                 "path.png", "rotation.png", "errors.png", "tensions.png"):
        assert (out / name).stat().st_size > 0, name
    result = Result.load(out)
    assert result.pose.shape == (31, 3) and np.all(np.isfinite(result.pose))
    pose = np.loadtxt(out / "pose.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(pose[:, 1:4], result.pose, rtol=1e-8, atol=1e-12)


def test_bad_input_exits_with_the_field_named_and_no_traceback(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text('name = "bad"\n[platform]\nmass = -2.5\n')
    done = _cdpr("run", str(scene), check=False)
    assert done.returncode == 2
    assert "platform.mass" in done.stderr and "Traceback" not in done.stderr


def test_every_command_has_help_with_an_example():
    for command in ("run", "scenes", "compare", "study", "view", "animate"):
        done = _cdpr(command, "--help")
        assert "example" in done.stdout, command


def test_scenes_lists_the_shipped_scenes():
    done = _cdpr("scenes")
    for name in ("paper-circle", "paper-circle-slow", "paper-catenary", "paper-catenary-fixed"):
        assert name in done.stdout


# --------------------------------------------------------------------------- a new user's defects (issue 11)

import signal
import time
from dataclasses import replace

from cdpr_exu.scenes.scene import load_scene, save_scene


def _strict_json(path):
    """Parse ``path`` as strict JSON: the NaN/Infinity tokens are refused, as strict parsers do."""
    def refuse(token):
        raise AssertionError(f"{path.name} holds the non-standard token {token}")
    return json.loads(path.read_text(), parse_constant=refuse)


def _scene_file(tmp_path, name, base="paper-circle", **solver):
    scene = load_scene(base)
    path = tmp_path / f"{name}.toml"
    save_scene(scene.with_changes(solver=replace(scene.solver, **solver)), path)
    return path


@pytest.mark.parametrize("command", [["run", "paper-circle"], ["static", "paper-catenary-fixed"],
                                     ["compare", "paper-circle"],
                                     ["study", "sweep", "paper-circle", "--param", "platform.mass=2,3"]])
def test_out_naming_an_existing_file_is_refused_before_any_work(tmp_path, command):
    taken = tmp_path / "taken.txt"
    taken.write_text("keep me")
    done = _cdpr(*command, "--out", str(taken), check=False)
    assert done.returncode == 2, done.stderr
    assert "is an existing file" in done.stderr and "Traceback" not in done.stderr
    assert "comparing controllers" not in done.stdout  # refused before the first controller ran
    assert taken.read_text() == "keep me"


def test_short_run_writes_strict_json_with_null_and_a_reason_instead_of_nan(tmp_path):
    out = tmp_path / "short"
    done = _cdpr("run", "paper-circle", "--end-time", "0.2", "--out", str(out), "--no-figures")
    summary = _strict_json(out / "summary.json")
    settled = summary["after_start_up"]
    assert settled["max_position_error_m"] is None and "no sample at or after t = 1 s" in settled["notes"][0]
    assert summary["max_position_error_m"] > 0  # the whole run's figures exist
    assert "nan" not in done.stdout.lower() and "n/a" in done.stdout
    assert "-0.00 " not in done.stdout


def test_compare_exits_3_when_every_controller_fails_and_keeps_the_partial_results(tmp_path):
    scene = _scene_file(tmp_path, "newton", end_time=0.5, max_newton_iterations=1)  # Newton cannot converge
    out = tmp_path / "cmp"
    # At full speed from t = 0 (the smooth start of `cdpr compare` lets one Newton iteration do).
    done = _cdpr("compare", str(scene), "--controllers", "ideal_ik", "--out", str(out), "--ramp-time", "0",
                 check=False)
    assert done.returncode == 3, done.stderr
    assert "did not complete: ideal_ik" in done.stderr
    assert _strict_json(out / "summary.json")["controllers"]["ideal_ik"]["status"].startswith("failed")


def test_run_failure_exits_3_and_exudyn_banners_do_not_leak(tmp_path):
    scene = _scene_file(tmp_path, "newton", end_time=0.5, max_newton_iterations=1)
    done = _cdpr("run", str(scene), "--out", str(tmp_path / "run"), "-q", check=False)
    assert done.returncode == 3
    text = done.stdout + done.stderr
    for banner in ("SOLVER FAILED", "showHints", "WARNING:", "Traceback"):
        assert banner not in text, banner
    assert "Likely cause" in done.stderr
    summary = _strict_json(tmp_path / "run" / "summary.json")  # the failed run's figures: null, never NaN
    assert summary["status"].startswith("failed") and summary["after_start_up"]["max_position_error_m"] is None


def test_static_failure_says_why_and_writes_the_scene_and_the_last_state(tmp_path):
    base = load_scene("paper-catenary")
    stiff = base.with_changes(exits=[replace(p, contact_stiffness=1e12) for p in base.exits],
                              solver=replace(base.solver, step_size=2e-2))  # Newton fails within 2 s
    path = tmp_path / "stiff.toml"
    save_scene(stiff, path)
    out = tmp_path / "static"
    done = _cdpr("static", str(path), "--out", str(out), "--max-time", "2", check=False)
    assert done.returncode == 3, done.stderr
    assert "Likely cause" in done.stderr and "SOLVER FAILED" not in done.stdout + done.stderr
    summary = _strict_json(out / "summary.json")
    assert summary["status"].startswith("failed") and 0.0 <= summary["failure_time_s"] <= 2.0
    assert summary["last_state"]["platform_pose"] is not None and (out / "scene.toml").is_file()


def test_two_runs_write_identical_files_apart_from_timing_json(tmp_path):
    """Issue 11.12: dates (summary, solution file header, zip members) and wall times are kept out of every file but timing.json."""
    for name in ("a", "b"):
        _cdpr("run", "paper-circle", "--end-time", "0.2", "--out", str(tmp_path / name), "-q")
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files == sorted(p.name for p in (tmp_path / "b").iterdir())
    assert {"summary.json", "result.npz", "solution.sol", "pose.csv", "overview.png", "timing.json"} <= set(files)
    changed = [f for f in files if (tmp_path / "a" / f).read_bytes() != (tmp_path / "b" / f).read_bytes()]
    assert changed in ([], ["timing.json"]), changed


def test_a_directory_given_as_the_scene_is_named_a_directory(tmp_path):
    done = _cdpr("run", str(tmp_path), check=False)
    assert done.returncode == 2 and "is a directory" in done.stderr


#: Scene files that are no TOML scene, and what the refusal says (issue 23.11: the first two were
#: UnicodeDecodeError tracebacks, exit 1).
MALFORMED_FILES = {
    "latin-1": (b'name = "caf\xe9"\n', "is not UTF-8 TOML: byte 11 is 0xe9"),
    "binary": (bytes(range(128, 256)) * 3, "is not UTF-8 TOML: byte 0 is 0x80"),
    "NUL bytes": (b"\x00\x01\x02", "is not valid TOML: Invalid statement"),
    "empty": (b"", "lacks pulleys, platform, trajectory"),
    "TOML syntax error": (b"name = 'x'\n[cable\n", "is not valid TOML: Expected ']'"),
    "spatial, Latin-1": (b'dimension = 3\nname = "caf\xe9"\n', "is not UTF-8 TOML: byte 25 is 0xe9"),
}


@pytest.mark.parametrize("kind", list(MALFORMED_FILES))
@pytest.mark.parametrize("command", ["run", "static"])
def test_a_scene_file_that_is_no_toml_scene_exits_2_naming_the_file(tmp_path, capsys, command, kind):
    from cdpr_exu.cli import main

    content, words = MALFORMED_FILES[kind]
    path = tmp_path / "scene.toml"
    path.write_bytes(content)
    assert main([command, str(path)]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"cdpr: error: scene {'file ' if 'UTF-8' in words else ''}'{path}'"), error
    assert words in error, error


def test_static_output_numbers_cables_from_one_and_prints_no_negative_zero():
    done = _cdpr("static", "paper-catenary-fixed")
    assert "cable 1:" in done.stdout and "cable 2:" in done.stdout and "cable 0" not in done.stdout
    assert "-0.000" not in done.stdout


def test_every_help_documents_the_exit_codes():
    for command in (["run"], ["static"], ["compare"], ["study", "sweep"], ["study", "accuracy"], ["animate"],
                    ["view"], ["scenes"], []):
        done = _cdpr(*command, "--help")
        assert "exit codes" in done.stdout and "130" in done.stdout, command


@pytest.mark.slow
def test_ctrl_c_saves_what_was_computed_prints_one_line_and_exits_130(tmp_path):
    out = tmp_path / "run"
    process = subprocess.Popen([sys.executable, "-m", "cdpr_exu.cli", "run", "paper-circle", "--out", str(out), "-q"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    solution = out / "solution.sol"
    while time.monotonic() < deadline and (not solution.exists() or solution.stat().st_size < 20_000):
        time.sleep(0.2)  # wait until the solver has written a few samples
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    assert "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1 and "interrupted" in stderr
    summary = _strict_json(out / "summary.json")
    assert summary["status"].startswith("interrupted") and 0 < summary["simulated_time_s"] < 10
    assert Result.load(out).time.size > 1


def _scene_ending_above_the_pulleys(tmp_path):
    """A paper scene whose point_to_point ends at z = +1 m, above the pulleys (z = 0):
    its file, and an output folder path that does not exist yet."""
    from cdpr_exu.scenes.trajectories import PointToPointTrajectory

    base = load_scene("paper-circle")
    scene = base.with_changes(trajectory=PointToPointTrajectory(start=(0.0, -2.0, 0.0), end=(0.0, 1.0, 0.0),
                                                                duration=2.0),
                              solver=replace(base.solver, end_time=3.0))
    path = tmp_path / "above.toml"
    save_scene(scene, path)
    return path, tmp_path / "above"


def test_an_unreachable_reference_exits_2_naming_time_and_pose_before_anything_is_written(tmp_path):
    """Issue 11.1: a point_to_point ending at z = +1 m (above the pulleys, at z = 0) ran under
    ideal IK with a 168.5 cm error and exit 0. It is refused before any simulation, with the
    time and the pose; the output folder holds nothing (no scene.toml of a run that never ran)."""
    path, out = _scene_ending_above_the_pulleys(tmp_path)
    done = _cdpr("run", str(path), "--out", str(out), check=False)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert re.search(r"the reference pose \[0\.0, 0\.\d+, 0\.0\] \(x \[m\], z \[m\], rotation \[rad\]\) at t = 1\.\d{3} s",
                     done.stderr), done.stderr
    assert "cannot hold the platform's weight" in done.stderr and "platform.mass" in done.stderr
    assert list(out.iterdir()) == []  # nothing written: no scene.toml, no summary


def test_compare_refuses_an_unreachable_reference_with_exit_2_before_any_run(tmp_path):
    """Issue 11.1 and 11.4: `cdpr compare` on a reference above the pulleys exited 3 with six
    identical "refused" rows; it is bad input (exit 2), refused once, before any run."""
    path, out = _scene_ending_above_the_pulleys(tmp_path)
    done = _cdpr("compare", str(path), "--out", str(out), check=False)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert "cannot hold the platform's weight" in done.stderr
    assert "refused" not in done.stdout  # no per-controller rows: nothing ran
    assert not out.exists() or list(out.iterdir()) == []


def test_sweep_csv_leaves_not_applicable_cells_empty_and_its_json_is_strict(tmp_path):
    """Issue 11.2: study.csv wrote `nan` (failure_time_s of completed runs, every figure of a
    refused run); such cells are empty now, and study.json holds null."""
    import csv

    out = tmp_path / "sweep"
    done = _cdpr("study", "sweep", "paper-circle", "--end-time", "0.2", "--param", "platform.mass=2.5,-1",
                 "--workers", "1", "--out", str(out), "-q", check=False)
    assert done.returncode == 3, done.stderr  # one run refused: "at least one run failed"
    text = (out / "study.csv").read_text()
    assert "nan" not in text.lower()
    with open(out / "study.csv", newline="") as handle:
        completed, refused = list(csv.DictReader(handle))
    assert completed["status"] == "completed" and completed["failure_time_s"] == ""
    assert float(completed["max_position_error_m"]) > 0.0 and float(completed["simulated_time_s"]) == 0.2
    assert refused["status"].startswith("refused: platform.mass must be positive")
    assert refused["max_position_error_m"] == "" and refused["failure_time_s"] == ""
    rows = _strict_json(out / "study.json")["rows"]
    assert rows[0]["failure_time_s"] is None and rows[1]["max_position_error_m"] is None


@pytest.mark.slow
def test_the_readme_command_writes_the_committed_result_folder_byte_for_byte(tmp_path):
    """Issue 11.12, as the README promises: `cdpr run paper-circle --out results/paper_circle`
    leaves `git status` clean. The same command into a copy of the committed folder (which
    also holds variants.* of examples/paper_reproduction.py, and a stale timing.json) rewrites
    every tracked file byte for byte, removes none and adds only the untracked timing.json
    (issue 23.15: a run clears only the files a run writes). Fails when the code moved the
    answer and the committed results were not regenerated."""
    import shutil
    from pathlib import Path

    committed = Path(__file__).resolve().parents[1] / "results" / "paper_circle"
    tracked = sorted(p.name for p in committed.iterdir() if p.name != "timing.json")
    out = tmp_path / "paper_circle"
    shutil.copytree(committed, out)
    (out / "timing.json").write_text('{"wall_time_s": 1e9}\n')
    _cdpr("run", "paper-circle", "--out", str(out), "-q")
    written = sorted(p.name for p in out.iterdir() if p.name != "timing.json")
    assert written == tracked
    assert {"summary.json", "result.npz", "solution.sol", "pose.csv", "scene.toml", "overview.png",
            "variants.md"} <= set(written)
    changed = [name for name in written if (committed / name).read_bytes() != (out / name).read_bytes()]
    assert changed == [], f"regenerate results/paper_circle: {changed} differ from what the code writes"
    assert json.loads((out / "timing.json").read_text())["wall_time_s"] < 1e9  # this run's, not the stale one


def test_ctrl_c_between_two_compared_controllers_keeps_the_ones_done(tmp_path, monkeypatch):
    """Issue 11.6: a Ctrl-C that fell between two runs of `cdpr compare` left an empty
    folder. The interrupt is sent the moment the first controller's row is printed."""
    import io
    import signal

    from cdpr_exu.cli.compare import print_controller_row
    from cdpr_exu.studies.comparison import compare_controllers

    class InterruptAfterFirstRow(io.StringIO):
        def write(self, text):
            if "ideal_ik" in text:
                # raise_signal sends it to this thread, so KeyboardInterrupt comes right after this call; os.kill
                # to the process could land on another thread (pytest-xdist's) and come late, inside the next run,
                # which keeps what it had as an interrupted run (the test failed so under load)
                signal.raise_signal(signal.SIGINT)
            return super().write(text)

    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=0.3))
    out = tmp_path / "compare"
    monkeypatch.setattr("sys.stdout", InterruptAfterFirstRow())
    with pytest.raises(KeyboardInterrupt):
        compare_controllers(scene, ["ideal_ik", "tension_aware"], out=out, after=0.0, progress=False,
                            report=print_controller_row)
    summary = _strict_json(out / "summary.json")
    assert list(summary["controllers"]) == ["ideal_ik"]
    assert summary["controllers"]["ideal_ik"]["status"] == "completed"


# --------------------------------------------------------------------------- wall clock apart (issue 23.18)


def _written(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


def _same_apart_from_timing(first, second):
    """The names of the files that differ between two output folders, timing.json aside."""
    a, b = _written(first), _written(second)
    assert sorted(a) == sorted(b)
    return [name for name in sorted(a) if name != "timing.json" and a[name] != b[name]]


@pytest.mark.parametrize("dimension", ["planar", "spatial"])
def test_two_comparisons_write_identical_files_apart_from_timing_json(tmp_path, dimension):
    """Issue 23.18: "everything else a run writes is identical" was false for `cdpr compare`:
    each controller's wall time and real-time factor sat in summary.json and comparison.md's
    "wall time [s]" column. They are in timing.json now, and two comparisons write the same
    bytes in every other file (tables, pose CSVs, figures)."""
    from conftest import small_spatial_scene

    from cdpr_exu.scenes.scene import save_scene

    if dimension == "planar":
        scene, controllers = _scene_file(tmp_path, "short", end_time=0.3), ["ideal_ik", "tension_aware"]
    else:  # the small robot's 5 cm in 0.2 s is beyond the catenary controllers' workspace: ideal IK only
        scene, controllers = save_scene(small_spatial_scene(0.2), tmp_path / "small.toml"), ["ideal_ik"]
    for name in ("a", "b"):
        _cdpr("compare", str(scene), "--controllers", ",".join(controllers), "--after", "0",
              "--out", str(tmp_path / name), "-q")
    assert _same_apart_from_timing(tmp_path / "a", tmp_path / "b") == []
    assert "wall" not in (tmp_path / "a" / "comparison.md").read_text()
    timing = json.loads((tmp_path / "a" / "timing.json").read_text())
    assert sorted(timing["controllers"]) == controllers
    assert all(t["wall_time_s"] > 0 for t in timing["controllers"].values())


def test_two_sweeps_write_identical_files_apart_from_timing_json(tmp_path):
    """Issue 23.18, `cdpr study sweep`: study.csv and study.json held each run's wall time and
    real-time factor, and vs_<parameter>.png plotted the wall time; the figure now plots the
    Newton iterations, and the wall-clock figures are in timing.json only."""
    for name in ("a", "b"):
        _cdpr("study", "sweep", "paper-circle", "--end-time", "0.2", "--param", "platform.mass=2,3",
              "--workers", "1", "--after", "0", "--out", str(tmp_path / name), "-q")
    assert _same_apart_from_timing(tmp_path / "a", tmp_path / "b") == []
    header = (tmp_path / "a" / "study.csv").read_text().splitlines()[0].split(",")
    assert "wall_time_s" not in header and "real_time_factor" not in header and "newton_iterations" in header
    timing = json.loads((tmp_path / "a" / "timing.json").read_text())
    assert [r["wall_time_s"] > 0 for r in timing["rows"]] == [True, True] and "date" in timing


@pytest.mark.parametrize("scene, option, value", [("spatial-ipanema", "--ramp-time", "-1"),
                                                  ("spatial-ipanema", "--after", "-1"),
                                                  ("paper-circle", "--after", "-1"),
                                                  ("paper-circle", "--after", "nan"),
                                                  ("paper-circle", "--ramp-time", "nan")])
def test_compare_refuses_a_negative_or_nan_time_option_naming_it_before_any_run(tmp_path, scene, option, value):
    """Issue 23.14: `--ramp-time -1` was accepted on spatial scenes (it never reached a check),
    `--after -1` on both kinds."""
    out = tmp_path / "cmp"
    done = _cdpr("compare", scene, option, value, "--controllers", "ideal_ik", "--end-time", "0.05",
                 "--out", str(out), check=False)
    assert done.returncode == 2, done.stderr
    assert f"{option} must be" in done.stderr and "Traceback" not in done.stderr
    assert "comparing controllers" not in done.stdout and not out.exists()
