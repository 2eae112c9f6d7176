"""Tests of cdpr_exu.post.viewer: replaying a real run folder (solution file + scene).

One real 0.3 s run of the paper's circle is written into a folder by ``run_scene``,
then: the solution file reloads and fits the rebuilt model, ``cdpr view`` refuses
cleanly without a display (in a subprocess, since Exudyn would end the process),
``cdpr animate`` writes a GIF of the expected frames that are not blank, and the
drawing helpers (path thinning, camera) keep their promises.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from cdpr_exu.post import viewer
from cdpr_exu.cli import main, run_scene
from cdpr_exu.scenes.scene import load_scene, save_scene

#: Simulated time of the test run [s]; with the scene's output period of 0.01 s
#: the solution file holds 31 rows (t = 0, 0.01, ..., 0.3).
END_TIME = 0.3
EXPECTED_ROWS = 31

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """A run folder of the paper's circle over 0.3 s, written as `cdpr run --out` writes it.

    The paper's spring elements: with tension-only elements the start-up's snap-taut
    steps are shrunk, and the solution file's rows and the result's samples then lie up
    to a step after the output times (each the end of a real step, see
    cdpr_exu.run.simulate._Recorder). The row-for-row checks here need unshrunk steps.
    """
    from cdpr_exu.scenes.scene import Effects

    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=END_TIME), effects=Effects.from_preset("paper"))
    out = tmp_path_factory.mktemp("run") / "paper_circle"
    run_scene(scene, out, quiet=True, figures=False)
    return out


@pytest.fixture(scope="module")
def spatial_run_dir(tmp_path_factory) -> Path:
    """A run folder of a small spatial scene over 0.3 s (31 samples), as `cdpr run --out` writes it."""
    from conftest import small_spatial_scene

    from cdpr_exu.cli.run import run_scene

    out = tmp_path_factory.mktemp("spatial") / "small_spatial"
    run_scene(small_spatial_scene(END_TIME), out, quiet=True, figures=False)
    return out


def _env_without_display() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("DISPLAY", "WAYLAND_DISPLAY", "EXUDYN_SUPPRESS_UI_WINDOW_OPEN")}
    return env


# ============================================================================ solution file


def test_solution_file_reloads_with_one_row_per_output_time(run_dir):
    solution = viewer.load_solution(run_dir / viewer.SOLUTION_FILE)
    assert solution["nRows"] == EXPECTED_ROWS
    times = solution["data"][:, 0]
    np.testing.assert_allclose(times, np.linspace(0.0, END_TIME, EXPECTED_ROWS), atol=1e-9)


@pytest.mark.parametrize("decorate", [False, True], ids=["as_built", "decorated"])
def test_rebuilt_model_has_the_coordinates_of_the_solution_file(run_dir, decorate):
    """The drawing-only items of decorate_model add no coordinate: the file still fits."""
    replay = viewer.load_replay(run_dir, decorate=decorate)
    data = replay.model.mbs.systemData
    n_ode2, n_vel2, n_acc2, n_ode1, n_vel1, n_algebraic, n_data = replay.solution["columnsExported"]
    assert n_ode2 == data.ODE2Size() > 0
    assert n_vel2 in (0, data.ODE2Size()) and n_acc2 in (0, data.ODE2Size())
    assert (n_ode1, n_algebraic, n_data) == (data.ODE1Size(), data.AEsize(), data.DataSize())
    assert replay.solution["nColumns"] == sum(replay.solution["columnsExported"])
    assert replay.solution["data"].shape == (EXPECTED_ROWS, replay.solution["nColumns"] + 1)


def test_replayed_platform_pose_matches_the_saved_result(run_dir):
    """The solution file and result.npz describe the same run: same platform pose."""
    from cdpr_exu.results.result import Result

    result = Result.load(run_dir)
    pose = viewer.load_replay(run_dir, decorate=False).positions()["platform"]
    # both are the solver's state at the same output times; only float formatting differs
    np.testing.assert_allclose(pose, result.pose, atol=1e-9)


def test_solution_of_another_model_is_refused_naming_the_file(run_dir, tmp_path):
    changed = tmp_path / "changed"
    shutil.copytree(run_dir, changed)
    scene = load_scene(changed / viewer.SCENE_FILE)
    cables = tuple(replace(c, n_elements=c.n_elements + 1) for c in scene.cables)
    save_scene(scene.with_changes(cables=cables), changed / viewer.SCENE_FILE)
    with pytest.raises(viewer.SolutionMismatchError, match="solution.sol.*ODE2 coordinates"):
        viewer.load_replay(changed)


def test_missing_folder_and_files_are_named(run_dir, tmp_path):
    with pytest.raises(viewer.RunFolderError, match="does not exist"):
        viewer.run_files(tmp_path / "nowhere")
    partial = tmp_path / "partial"
    partial.mkdir()
    shutil.copy(run_dir / viewer.SCENE_FILE, partial)
    with pytest.raises(viewer.RunFolderError, match="solution.sol"):
        viewer.render_animation(partial)
    assert main(["animate", str(partial)]) == 2


# ============================================================================ spatial runs (issue 23.8)


def test_a_spatial_run_writes_scene_pose_csv_and_solution_file_as_every_run(spatial_run_dir):
    """Issue 23.8: spatial runs wrote no scene.toml, pose.csv or solution.sol, which the README
    promises for `cdpr run`. pose.csv holds time, pose and reference with units in the header,
    the numbers of result.npz to its 9 significant digits."""
    from conftest import small_spatial_scene

    from cdpr_exu.scenes.scene import load_scene

    for name in ("scene.toml", "result.npz", "pose.csv", "summary.json", "solution.sol"):
        assert (spatial_run_dir / name).stat().st_size > 0, name
    assert load_scene(spatial_run_dir / "scene.toml") == small_spatial_scene(END_TIME)
    header = (spatial_run_dir / "pose.csv").read_text().splitlines()[0].split(",")
    assert header == ["time_s", "x_m", "y_m", "z_m", "rotation_x_rad", "rotation_y_rad", "rotation_z_rad",
                      "x_ref_m", "y_ref_m", "z_ref_m", "rotation_x_ref_rad", "rotation_y_ref_rad", "rotation_z_ref_rad"]
    table = np.loadtxt(spatial_run_dir / "pose.csv", delimiter=",", skiprows=1)
    with np.load(spatial_run_dir / "result.npz") as data:
        np.testing.assert_allclose(table[:, 0], data["time"], rtol=1e-8, atol=1e-12)
        np.testing.assert_allclose(table[:, 1:7], data["platform_pose"], rtol=1e-8, atol=1e-12)
        np.testing.assert_allclose(table[:, 7:], data["reference_pose"], rtol=1e-8, atol=1e-12)


def test_a_spatial_solution_file_replays_in_the_rebuilt_robot_at_the_recorded_poses(spatial_run_dir):
    """The solution file fits the robot rebuilt from scene.toml (as SolutionViewer needs), row for
    row at the result's times, and each row puts the platform where result.npz recorded it: both are
    the solver's state at the same step ends (31 unshrunk steps), so they agree to round-off."""
    replay = viewer.load_replay(spatial_run_dir)
    assert replay.scene.dimension == 3 and replay.n_rows == EXPECTED_ROWS
    with np.load(spatial_run_dir / "result.npz") as data:
        np.testing.assert_allclose(replay.times, data["time"], atol=1e-9)
        np.testing.assert_allclose(replay.platform_pose(), data["platform_pose"], atol=1e-9)


def test_the_rebuilt_spatial_robot_draws_in_the_views_camera(spatial_run_dir):
    """What `cdpr view` shows of a spatial run, drawn headless by Exudyn's raytracer at the view's
    settings: the last row's cables and nodes on a white background (not a blank frame)."""
    import exudyn as exu
    from exudyn.utilities import SetSolutionState

    replay = viewer.load_replay(spatial_run_dir)
    viewer._style_spatial(replay, size=(160, 120))
    for configuration in (exu.ConfigurationType.Current, exu.ConfigurationType.Visualization):
        SetSolutionState(replay.model.mbs, replay.solution, replay.n_rows - 1, configuration)
    image = np.asarray(replay.model.mbs.GetSystemContainer().renderer.RedrawAndGetImage(useRaytracer=True))[:, :, :3]
    assert image.shape[:2] == (120, 160)
    drawn = (image < 200).any(axis=2).mean()  # share of pixels that are not background
    assert 0.001 < drawn < 0.5, drawn


def test_a_rerun_from_the_written_spatial_scene_writes_the_same_result(spatial_run_dir, tmp_path):
    """scene.toml is the scene as run: `cdpr run` on it writes the same result, pose table and
    (date blanked) solution file byte for byte."""
    out = tmp_path / "rerun"
    assert main(["run", str(spatial_run_dir / "scene.toml"), "--out", str(out), "--no-figures",
                 "--no-error-estimate", "-q"]) == 0
    for name in ("result.npz", "pose.csv", "solution.sol", "scene.toml"):
        assert (out / name).read_bytes() == (spatial_run_dir / name).read_bytes(), name


def test_view_of_a_spatial_run_without_display_exits_1_with_a_hint(spatial_run_dir):
    """Issue 23.8: `cdpr view` on a spatial run said the folder lacks the scene.toml that `cdpr run`
    writes. It now finds the run and refuses only for the missing display, as on planar runs."""
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "view", str(spatial_run_dir)],
                          env=_env_without_display(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 1, done.stderr
    assert "no display" in done.stderr and "cdpr animate" in done.stderr and "not found" not in done.stderr


# ============================================================================ view


def test_display_problem_is_reported_without_display_variables(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if sys.platform in ("win32", "darwin"):
        pytest.skip("DISPLAY only matters on X11/Wayland systems")
    problem = viewer.display_problem()
    assert problem is not None and ("DISPLAY" in problem or "switched off" in problem)


def test_view_without_display_exits_with_code_1_and_a_hint(run_dir):
    """Exudyn would end the process on a missing display: the check must come first."""
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "view", str(run_dir)],
                          env=_env_without_display(), capture_output=True, text=True, timeout=120)
    assert done.returncode == 1, done.stderr  # not killed by a signal (negative), not a crash
    assert "no display" in done.stderr
    assert "cdpr animate" in done.stderr


# ============================================================================ animate


def test_animate_writes_gif_with_one_frame_per_chosen_row(run_dir, tmp_path):
    out, frames_dir = tmp_path / "anim.gif", tmp_path / "frames"
    code = main(["animate", str(run_dir), "--out", str(out), "--every", "5", "--size", "160x120",
                 "--fps", "10", "--frames-dir", str(frames_dir), "--quiet"])
    assert code == 0
    expected = len(range(0, EXPECTED_ROWS, 5))  # rows 0, 5, ..., 30
    with Image.open(out) as gif:
        assert gif.n_frames == expected
        assert gif.size == (160, 120)
        assert gif.info["duration"] == 100  # 10 frames/s
        for index in range(gif.n_frames):
            gif.seek(index)
            assert np.asarray(gif.convert("L"), dtype=float).var() > 0.0, f"frame {index} is blank"
    assert sorted(p.name for p in frames_dir.iterdir()) == [f"frame_{i:05d}.png" for i in range(expected)]


def test_animation_frames_show_the_pulleys_where_the_camera_puts_them(run_dir, tmp_path):
    """The raytracer's view and Camera.to_pixels (used for the caption overlay) agree."""
    size = (320, 240)
    viewer.render_animation(run_dir, tmp_path / "a.gif", every=100, size=size, frames_dir=tmp_path)
    frame = np.asarray(Image.open(tmp_path / "frame_00000.png").convert("RGB"), dtype=int)
    replay = viewer.load_replay(run_dir)
    camera = viewer.fit_camera(viewer._view_points(replay), size)
    for pulley in replay.scene.exits:
        inside = camera.to_pixels(np.array(pulley.center) + [0.0, -0.5 * pulley.radius]).round().astype(int)
        outside = camera.to_pixels(np.array(pulley.center) + [0.0, -1.4 * pulley.radius]).round().astype(int)
        # disc: shaded grey (measured about 225); background: white
        assert frame[inside[1], inside[0]].max() < 245
        assert frame[outside[1], outside[0]].min() == 255


def test_mp4_has_one_frame_per_chosen_row(run_dir, tmp_path):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    out, _, _ = viewer.render_animation(run_dir, tmp_path / "anim.mp4", every=10, size=(160, 120), fps=10)
    reader = imageio_ffmpeg.read_frames(str(out))
    meta = next(reader)
    assert tuple(meta["size"]) == (160, 120)
    assert sum(1 for _ in reader) == len(range(0, EXPECTED_ROWS, 10))


def test_unknown_animation_type_is_refused_before_rendering(run_dir, tmp_path):
    with pytest.raises(viewer.CdprError, match=r"\.gif or \.mp4"):
        viewer.render_animation(run_dir, tmp_path / "anim.avi")
    assert not (tmp_path / "anim.avi").exists()


def test_animation_inside_a_file_is_refused_naming_the_file(run_dir, tmp_path):
    taken = tmp_path / "taken.txt"
    taken.write_text("keep me")
    with pytest.raises(viewer.CdprError, match="is a file, not a folder"):
        viewer.render_animation(run_dir, taken / "anim.gif")
    assert taken.read_text() == "keep me"


@pytest.mark.parametrize("fps", ["0", "nan", "-5", "inf", "101"])
@pytest.mark.parametrize("dimension", ["planar", "spatial"])
def test_a_bad_fps_is_refused_naming_it_before_any_work_for_both_dimensions(run_dir, spatial_run_dir, tmp_path,
                                                                             capsys, dimension, fps):
    """Issue 23.12: on spatial runs --fps 0 and nan crashed with tracebacks, -5 after the whole
    rendering (49 s on CoGiRo), inf wrote a GIF of zero frame times; 101 frames/s is more than
    a GIF's hundredths of a second can store. One check, before anything is written, for both."""
    folder = run_dir if dimension == "planar" else spatial_run_dir
    out, frames = tmp_path / "a.gif", tmp_path / "frames"
    code = main(["animate", str(folder), "--fps", fps, "--out", str(out), "--frames-dir", str(frames), "-q"])
    assert code == 2
    assert "--fps" in capsys.readouterr().err
    assert not out.exists() and not frames.exists()


def test_spatial_animation_writes_its_frames_into_frames_dir(spatial_run_dir, tmp_path):
    """Issue 23.12: --frames-dir was ignored on spatial runs. The frames are the animation's, one per
    chosen sample, of the asked size, none blank."""
    out, frames_dir = tmp_path / "spatial.gif", tmp_path / "frames"
    code = main(["animate", str(spatial_run_dir), "--out", str(out), "--every", "5", "--size", "160x120",
                 "--fps", "10", "--frames-dir", str(frames_dir), "--quiet"])
    assert code == 0
    expected = len(range(0, EXPECTED_ROWS, 5))  # samples 0, 5, ..., 30
    with Image.open(out) as gif:
        assert gif.n_frames == expected and gif.size == (160, 120) and gif.info["duration"] == 100
    names = sorted(p.name for p in frames_dir.iterdir())
    assert names == [f"frame_{i:05d}.png" for i in range(expected)]
    for name in names:
        with Image.open(frames_dir / name) as frame:
            assert frame.size == (160, 120)
            assert np.asarray(frame.convert("L"), dtype=float).var() > 0.0, f"{name} is blank"


# ============================================================================ helpers


def test_thin_polyline_keeps_ends_and_spacing():
    x = np.arange(0.0, 102.0)  # 0, 1, ..., 101: whole numbers, so the spacing is exact
    points = np.column_stack([x, np.zeros_like(x)])
    thinned = viewer.thin_polyline(points, 5.0)
    np.testing.assert_allclose(thinned[:, 0], [*range(0, 100, 5), 101.0])  # 100 gives way to the end, 1 away
    np.testing.assert_allclose(thinned[[0, -1]], points[[0, -1]])


def test_fit_camera_shows_every_point_below_the_caption():
    points = np.array([[-2.0, 0.3], [2.0, -2.4], [0.5, np.nan]])
    camera = viewer.fit_camera(points, (640, 480), caption_band=0.1)
    pixels = camera.to_pixels(points[:2])
    assert np.all(pixels[:, 0] >= 0) and np.all(pixels[:, 0] <= 640)
    assert np.all(pixels[:, 1] >= 0.1 * 480) and np.all(pixels[:, 1] <= 480)


@pytest.mark.parametrize("text", ["640", "axb", "10x10", "640x480x3"])
def test_parse_size_refuses_bad_sizes(text):
    with pytest.raises(ValueError, match="size"):
        viewer.parse_size(text)



# ============================================================================ a folder of an earlier run (issue 23.15)


def test_a_spatial_run_into_a_planar_runs_folder_leaves_none_of_the_planar_runs_files(run_dir, spatial_run_dir,
                                                                                      tmp_path):
    """Issue 23.15: a spatial run into a planar run's folder kept that run's scene.toml,
    solution.sol and figures, and `cdpr view` replayed the old run. Now the folder holds the
    new run's files only, plus what no run writes (a user's notes)."""
    folder = tmp_path / "reused"
    shutil.copytree(run_dir, folder)
    (folder / "snapshots.png").write_bytes(b"a planar figure the spatial run does not draw")
    (folder / "notes.txt").write_text("mine")
    assert main(["run", str(spatial_run_dir / "scene.toml"), "--out", str(folder), "--no-figures",
                 "--no-error-estimate", "-q"]) == 0
    assert sorted(p.name for p in folder.iterdir()) == sorted([p.name for p in spatial_run_dir.iterdir()] + ["notes.txt"])
    assert (folder / "notes.txt").read_text() == "mine"
    assert viewer.load_replay(folder).model.items.chains  # `cdpr view` replays the new run


def test_a_comparison_into_a_run_folder_is_refused_before_any_work(run_dir, tmp_path, capsys):
    folder = tmp_path / "run"
    shutil.copytree(run_dir, folder)
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    assert main(["compare", "paper-circle", "--controllers", "ideal_ik", "--out", str(folder), "-q"]) == 2
    assert "holds the output of `cdpr run`" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
