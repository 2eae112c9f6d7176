"""Tests of cdpr_exu.post.plots: every figure is written as a readable PNG of a sensible size,
from one short real run of the paper's circle, also when the run is cut short."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from matplotlib.image import imread

from cdpr_exu.post import plots
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.run.simulate import simulate


@pytest.fixture(scope="module")
def run():
    """One real 1 s run of the paper's circle (about 0.3 s of simulation)."""
    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=1.0))
    return scene, simulate(scene)


def _cut_short(result, keep_fraction=0.5, nan_rows=5):
    """The result's first ``keep_fraction`` of samples, with NaN in the last rows, as a failed run."""
    keep = max(nan_rows, int(len(result.time) * keep_fraction))

    def head(a):
        a = np.array(a[:keep], dtype=float)
        a[-nan_rows:] = np.nan
        return a

    return replace(
        result,
        time=np.array(result.time[:keep], dtype=float),
        pose=head(result.pose),
        velocity=head(result.velocity),
        reference=np.array(result.reference[:keep], dtype=float),
        nodes=[head(a) for a in result.nodes],
        node_velocities=[head(a) for a in result.node_velocities],
        tensions=[head(a) for a in result.tensions],
        paid_out=head(result.paid_out),
        pulley_penetration=head(result.pulley_penetration),
        status="failed: cut short by the test",
        failure_time=float(result.time[keep - nan_rows]),
    )


def _assert_png(path, min_width=400, min_height=250):
    """The file exists, is non-empty, reads back as an image of at least the given pixels,
    and is not blank (a drawn figure has more than one colour)."""
    assert path.exists() and path.stat().st_size > 5_000, path
    image = imread(path)
    height, width = image.shape[:2]
    assert width >= min_width and height >= min_height, (path, image.shape)
    assert width <= 4000 and height <= 4000, (path, image.shape)
    assert np.ptp(image[..., :3]) > 0.5, path


def test_each_figure_writes_a_png_of_plausible_size(run, tmp_path):
    scene, result = run
    _assert_png(plots.plot_snapshots(scene, result, tmp_path / "s.png", times=(0, 0.5, 1.0)), min_width=900)
    _assert_png(plots.plot_path(scene, result, tmp_path / "p.png"))
    _assert_png(plots.plot_rotation(result, tmp_path / "r.png"))
    _assert_png(plots.plot_errors(result, tmp_path / "e.png"))
    _assert_png(plots.plot_tensions(scene, result, tmp_path / "t.png"))


def test_figures_are_written_into_folders_that_do_not_exist_yet(run, tmp_path):
    scene, result = run
    path = plots.plot_path(scene, result, tmp_path / "new" / "deeper" / "p.png")
    _assert_png(path)


def test_overview_returns_every_file_with_its_fixed_name(run, tmp_path):
    scene, result = run
    paths = plots.plot_overview(scene, result, tmp_path / "figures")
    assert [p.name for p in paths] == list(plots.OVERVIEW_FILES.values())
    for path in paths:
        _assert_png(path)
    assert imread(paths[-1]).shape[1] >= 1200  # the 2x2 overview is wide


def test_comparison_writes_paths_and_errors(run, tmp_path):
    scene, result = run
    shifted = replace(result, pose=result.pose + np.array([0.02, -0.01, 0.0]))
    paths = plots.plot_comparison(scene, {"real": result, "shifted": shifted, "cut": _cut_short(result)}, tmp_path)
    assert [p.name for p in paths] == ["comparison_paths.png", "comparison_errors.png"]
    for path in paths:
        _assert_png(path)


def test_a_run_cut_short_with_nan_rows_still_plots(run, tmp_path):
    scene, result = run
    partial = _cut_short(result)
    assert np.isnan(partial.pose[-1]).all()
    # Snapshot instants after the end of the data get a "not reached" panel.
    _assert_png(plots.plot_snapshots(scene, partial, tmp_path / "s.png", times=(0, 0.25, 1.0)), min_width=900)
    for path in plots.plot_overview(scene, partial, tmp_path / "overview"):
        _assert_png(path)


def test_a_run_with_no_valid_sample_still_plots(run, tmp_path):
    scene, result = run
    empty = _cut_short(result, keep_fraction=0.0, nan_rows=7)
    assert np.isnan(empty.pose).all()
    for path in plots.plot_overview(scene, empty, tmp_path):
        _assert_png(path, min_width=300, min_height=200)


def _edges_are_background(path):
    """True if the outermost pixel rows and columns of the PNG are plain white background.

    An artist cut at the image border (a legend or a title wider than the figure)
    leaves ink on the outermost pixels; a figure that holds all its artists has a
    white margin there.
    """
    image = imread(path)[..., :3]
    edges = np.concatenate([image[0], image[-1], image[:, 0], image[:, -1]])
    return bool(np.all(edges > 0.97))


def test_comparison_legend_with_the_long_controller_names_is_not_cut(run, tmp_path):
    scene, result = run
    names = ["reference", "ideal_ik", "tension_aware_dynamic_chordal", "closed_loop_tension_aware",
             "tension_aware_chain"]
    results = {name: result for name in names[1:]}
    for path in plots.plot_comparison(scene, results, tmp_path):
        assert _edges_are_background(path), path


def test_overview_of_a_failed_run_keeps_its_long_title_inside_the_image(run, tmp_path):
    scene, result = run
    failed = replace(_cut_short(result), status="failed: " + "the run failed for a reason with a long text " * 4)
    for path in plots.plot_overview(scene, failed, tmp_path):
        assert _edges_are_background(path), path
