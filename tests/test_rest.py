"""The static mode (``cdpr_exu.run.rest``) on the real solver: the paper's scenario-2 scenes at rest.

The force balances below need no reference solution: at rest, the forces the supports
exert on a free span (the platform joint, the winch constraints or the cut at the
pulley) and its weight must cancel, whatever the shape. Internal forces (axial,
bending, damping) cancel in the sum over the span, so only Newton's residual and the
inertia of a residual motion are left.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.cli import main
from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.core.output import ZIP_DATE
from cdpr_exu.run.rest import RestState, solve_rest
from cdpr_exu.scenes.scene import Effects, load_scene

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def fixed():
    scene = load_scene("paper-catenary-fixed")
    return scene, solve_rest(scene)


@pytest.fixture(scope="module")
def pulleys():
    scene = load_scene("paper-catenary")
    return scene, solve_rest(scene)


def test_paper_scene_comes_to_rest_below_the_tolerance(fixed):
    scene, rest = fixed
    assert rest.max_node_speed_m_s < 1e-6
    assert rest.time_s >= scene.solver.end_time  # the scene's own run first, extended if needed
    assert rest.method == "dynamic+static"
    # The static polish moves the settled state by about v tau (tau ~ 1 s, the Kelvin-Voigt
    # time constant): below 1e-6 m for v < 1e-6 m/s (measured 2e-7 m).
    assert rest.static_shift_m < 1e-5


@pytest.mark.parametrize("which", ["fixed", "pulleys"])
def test_end_forces_balance_the_weight_of_each_free_span(which, request):
    scene, rest = request.getfixturevalue(which)
    # 1e-6 N against 5-15 N end forces: a static solution (Newton to 1e-10), measured
    # 1e-15 N (fixed ends) and 3e-11 N (pulleys, with the bending shear at the cut).
    np.testing.assert_allclose(rest.force_balance_residual(), 0.0, atol=1e-6)
    assert np.all(rest.span_weights_N > 0.0)
    # each cable pulls its support down and towards the platform, and the platform up
    assert np.all(rest.upper_forces_N[:, 1] < 0.0) and np.all(rest.platform_forces_N[:, 1] > 0.0)
    assert rest.upper_forces_N[0, 0] > 0.0 > rest.upper_forces_N[1, 0]


@pytest.mark.parametrize("which", ["fixed", "pulleys"])
def test_cables_hold_the_platform_weight(which, request):
    scene, rest = request.getfixturevalue(which)
    weight = scene.gravity * scene.platform.mass
    # 1e-6 N: at rest, as above (the joint reactions are Lagrange multipliers).
    np.testing.assert_allclose(rest.platform_forces_N.sum(axis=0), [0.0, weight], atol=1e-6)
    assert rest.platform_rotation_deg == 0.0  # a point mass: its rotation is locked, and irrelevant


def test_end_forces_hold_the_whole_weight_with_fixed_ends(fixed):
    scene, rest = fixed
    cables = sum(scene.gravity * c.node_masses().sum() for c in scene.cables)
    # 1e-6 N: at rest, as above.
    np.testing.assert_allclose(-rest.upper_forces_N.sum(axis=0), [0.0, cables + scene.gravity * scene.platform.mass],
                               atol=1e-6)


def test_fixed_end_free_span_is_the_whole_cable(fixed):
    scene, rest = fixed
    for i, cable in enumerate(scene.cables):
        assert rest.first_free_node[i] == 0
        np.testing.assert_array_equal(rest.upper_points_m[i], rest.nodes[i][0])
        np.testing.assert_allclose(rest.upper_points_m[i], scene.exits[i].point, atol=1e-12)
        polygon = np.linalg.norm(np.diff(rest.nodes[i], axis=0), axis=1).sum()
        assert rest.cable_stretched_length_m[i] == pytest.approx(polygon, rel=1e-15)
        assert rest.cable_unstrained_length_m[i] == cable.unstrained_length
        # stretched by T/EA ~ 1.5e-4 (10 to 16 N on EA = 7.9e4 N)
        assert 1e-4 < rest.cable_stretched_length_m[i] / cable.unstrained_length - 1 < 2e-4


def test_pulley_free_span_starts_where_the_cable_leaves_the_rim(pulleys):
    scene, rest = pulleys
    for i, (cable, pulley) in enumerate(zip(scene.cables, scene.exits)):
        first = rest.first_free_node[i]
        assert 0 < first < cable.n_elements
        center = np.asarray(pulley.center)
        distance = np.linalg.norm(rest.nodes[i] - center, axis=1)
        assert distance[first - 1] < pulley.radius and np.all(distance[first:] > pulley.radius)
        assert np.hypot(*(rest.upper_points_m[i] - center)) == pytest.approx(pulley.radius, rel=1e-12)
        # the straight piece from the leave point to the first free node is tangent to the rim
        radial = rest.upper_points_m[i] - center
        assert radial @ (rest.nodes[i][first] - rest.upper_points_m[i]) == pytest.approx(0.0, abs=1e-12)
        assert rest.cable_unstrained_length_m[i] < cable.unstrained_length
        assert rest.upper_points_m[i][1] > center[1]  # over the top, on the platform's side
    # the two cables mirror each other
    np.testing.assert_allclose(rest.cable_stretched_length_m[0], rest.cable_stretched_length_m[1], rtol=1e-9)


def test_settled_state_without_polish_balances_to_the_inertia_of_its_creep(fixed):
    scene, polished = fixed
    rest = solve_rest(scene, polish=False)
    assert rest.method == "dynamic" and rest.static_shift_m is None
    assert rest.max_node_speed_m_s < 1e-6
    # What is left is the inertia of the residual motion, about m v / tau with tau ~ 1 s:
    # 1e-6 N for 0.9 kg per span at 1e-6 m/s (measured 2e-7 N); 1e-4 N leaves margin.
    np.testing.assert_allclose(rest.force_balance_residual(), 0.0, atol=1e-4)
    # and it lies within v tau of the polished state
    np.testing.assert_allclose(rest.platform_position_m, polished.platform_position_m, atol=1e-5)


def test_scene_without_bending_damping_rests_by_bending_continuation():
    base = load_scene("paper-catenary-fixed")
    scene = base.with_changes(effects=Effects.from_preset("catenary", pulley_contact=False),
                              cables=tuple(replace(c, n_elements=8) for c in base.cables))
    rest = solve_rest(scene)
    assert rest.method == "bending-continuation+static"
    # a static solution, checked by 0.2 s of its own (undamped-swinging) dynamics:
    # it stays put to round-off (measured 2e-13 m/s)
    assert rest.max_node_speed_m_s < 1e-9
    assert all(t.min() > 0.0 for t in rest.tensions)  # the hanging branch, not one of pushing elements
    np.testing.assert_allclose(rest.force_balance_residual(), 0.0, atol=1e-6)


def test_scene_not_at_rest_in_time_raises_solver_failure():
    scene = load_scene("paper-catenary-fixed")
    with pytest.raises(SolverFailure, match="not at rest after 0.5 s"):
        solve_rest(scene, max_time=0.5)


def test_massless_cables_are_refused_before_any_run():
    scene = load_scene("paper-catenary-fixed").with_changes(effects=Effects.from_preset("elastic"))
    with pytest.raises(SceneError, match="cable_mass"):
        solve_rest(scene)
    with pytest.raises(SceneError, match="tolerance"):
        solve_rest(load_scene("paper-catenary-fixed"), tolerance=0.0)


def test_rest_state_saves_summary_and_arrays(fixed, tmp_path):
    _, rest = fixed
    paths = rest.save(tmp_path)
    data = np.load(paths["npz"])
    np.testing.assert_array_equal(data["nodes_0"], rest.nodes[0])
    np.testing.assert_array_equal(data["platform_position_m"], rest.platform_position_m)
    summary = json.loads(paths["summary"].read_text())
    assert summary["cable_stretched_length_m"] == rest.cable_stretched_length_m.tolist()
    assert isinstance(rest, RestState)
    with zipfile.ZipFile(paths["npz"]) as archive:  # a fixed member date: the same state gives the same bytes
        assert {info.date_time for info in archive.infolist()} == {ZIP_DATE}


def test_cli_static_writes_the_summary_keys_npz_and_figure(tmp_path, capsys):
    out = tmp_path / "static"
    assert main(["static", "paper-catenary-fixed", "--out", str(out)]) == 0
    assert "at rest after" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    for key in ("platform_position_m", "platform_rotation_deg", "cable_stretched_length_m",
                "cable_unstrained_length_m", "upper_forces_N", "platform_forces_N", "nodes_m",
                "element_tensions_N", "max_node_speed_m_s", "method", "definitions", "versions"):
        assert key in summary, key
    assert "date" in json.loads((out / "timing.json").read_text())  # the date lives apart from the figures
    assert len(summary["nodes_m"]) == 2 and len(summary["nodes_m"][0]) == 16
    assert summary["platform_position_m"][1] == pytest.approx(-1.7218, abs=1e-4)
    for name in ("rest.npz", "rest_profile.png"):
        assert (out / name).stat().st_size > 0, name


def test_cli_static_help_shows_an_example(capsys):
    with pytest.raises(SystemExit):
        main(["static", "--help"])
    assert "cdpr static paper-catenary-fixed --out" in capsys.readouterr().out
