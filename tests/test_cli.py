"""The ``cdpr`` command as a user runs it (subprocess), and the files it writes."""

import json
import subprocess
import sys

import numpy as np
import pytest

from cdpr_exu.result import Result


def _cdpr(*args, check=True):
    return subprocess.run([sys.executable, "-m", "cdpr_exu.cli", *args], capture_output=True, text=True,
                          check=check, timeout=600)


def test_run_writes_result_summary_solution_and_figures(tmp_path):
    out = tmp_path / "run"
    done = _cdpr("run", "paper-circle", "--end-time", "0.3", "--out", str(out))
    assert "max |error x|" in done.stdout and "written to" in done.stdout
    summary = json.loads((out / "summary.json").read_text())
    for key in ("max_abs_error_x_m", "max_abs_error_z_m", "max_abs_rotation_deg", "min_element_tension_N",
                "max_pulley_penetration_m", "wall_time_s", "simulated_time_s", "steps", "versions", "date"):
        assert key in summary, key
    assert summary["simulated_time_s"] == pytest.approx(0.3)
    assert summary["error_convention"] == "actual - reference"
    for name in ("result.npz", "pose.csv", "solution.sol", "scene.toml", "overview.png", "snapshots.png",
                 "path.png", "rotation.png", "errors.png", "tensions.png"):
        assert (out / name).stat().st_size > 0, name
    result = Result.load(out)
    assert result.platform_pose.shape == (31, 3) and np.all(np.isfinite(result.platform_pose))
    pose = np.loadtxt(out / "pose.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(pose[:, 1:4], result.platform_pose, rtol=1e-8, atol=1e-12)


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
