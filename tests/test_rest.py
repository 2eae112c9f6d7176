"""The static mode (``cdpr_exu.run.rest``) on the real solver: planar and spatial scenes at rest.

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
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from cdpr_exu.cli import main
from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.core.output import ZIP_DATE
from cdpr_exu.run.rest import Rest, solve_rest
from cdpr_exu.scenes.caspr import caspr_scene
from cdpr_exu.scenes.scene import Effects, load_scene, scene_from_dict
from test_spatial_scene import PLANAR_AS_SPATIAL

pytestmark = pytest.mark.slow

@cache
def shipped_rest(name: str) -> tuple:
    """A shipped scene and its rest, solved once per test process."""
    scene = load_scene(name)
    return scene, solve_rest(scene)


@pytest.fixture(scope="module")
def fixed():
    return shipped_rest("paper-catenary-fixed")


@pytest.fixture(scope="module")
def pulleys():
    return shipped_rest("paper-catenary")


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
    assert np.all(rest.upper_forces_N[:, 1] < 0.0) and np.all(rest.platform_forces[:, 1] > 0.0)
    assert rest.upper_forces_N[0, 0] > 0.0 > rest.upper_forces_N[1, 0]
    assert rest.rotation == 0.0  # a point mass: its rotation is locked, and irrelevant


@pytest.mark.parametrize("name", ["paper-catenary-fixed", "paper-catenary", "spatial-four-cable", "spatial-cogiro",
                                  "spatial-ipanema"])
def test_the_cables_hold_the_platform_in_force_and_moment_balance_every_element_taut(name):
    scene, rest = shipped_rest(name)
    space, weight = scene.space, scene.platform.mass * scene.gravity
    lift = np.zeros(space.position_size)
    lift[space.vertical] = weight
    pose = np.append(rest.position, rest.rotation)
    moments = space.moments(pose, np.asarray(scene.platform.anchors), rest.platform_forces).sum(axis=0)
    # Both are Exudyn's static solutions (Newton to 1e-9 relative; the planar forces are the joints'
    # Lagrange multipliers), and the penalty joints of a rigid platform move nothing in the balance:
    # 1e-8 of the weight (9.8 N, 49 N, 893 N, 245 N). Measured 0 in the plane, 1.4e-9 of it in space.
    assert rest.platform_forces.sum(axis=0) == pytest.approx(lift, abs=1e-8 * weight)
    assert moments == pytest.approx(np.zeros(space.rotation_size), abs=1e-8 * weight)
    assert np.all(rest.anchor_tensions > 0.0)
    # every element taut: the slackest of all (2 x 15 to 8 x 20) still carries 8.6 N (measured, the
    # paper's scene over pulleys); nothing is compressed
    assert rest.lowest_element_tension > 5.0 and rest.warnings == ()


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
    np.testing.assert_allclose(rest.position, polished.position, atol=1e-5)


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
    np.testing.assert_array_equal(data["platform_position_m"], rest.position)
    summary = json.loads(paths["summary"].read_text())
    assert summary["cable_stretched_length_m"] == rest.cable_stretched_length_m.tolist()
    assert isinstance(rest, Rest)
    with zipfile.ZipFile(paths["npz"]) as archive:  # a fixed member date: the same state gives the same bytes
        assert {info.date_time for info in archive.infolist()} == {ZIP_DATE}


PLANAR_KEYS = ("platform_rotation_deg", "cable_stretched_length_m", "cable_unstrained_length_m", "upper_forces_N",
               "platform_forces_N", "nodes_m", "element_tensions_N", "max_node_speed_m_s", "definitions")
SPATIAL_KEYS = ("dimension", "platform_rotation_vector_rad", "force_on_platform_N", "catenary_platform_position_m",
                "min_element_tension_N", "warnings")


@pytest.mark.parametrize("name, printed, keys, npz", [("paper-catenary-fixed", "at rest after", PLANAR_KEYS, True),
                                                     ("spatial-four-cable", "rotation vector", SPATIAL_KEYS, False)])
def test_cli_static_prints_the_pose_and_writes_a_strict_summary_and_the_figure(name, printed, keys, npz, tmp_path,
                                                                              capsys):
    out = tmp_path / "static"
    assert main(["static", name, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert printed in text and "platform at x =" in text and f"written to {out}/" in text
    summary = json.loads((out / "summary.json").read_text(), parse_constant=lambda c: pytest.fail(c))
    for key in ("scene", "method", "platform_position_m", "versions", *keys):
        assert key in summary, key
    assert "date" in json.loads((out / "timing.json").read_text())  # the date lives apart from the figures
    scene, rest = shipped_rest(name)
    assert summary["platform_position_m"] == rest.position.tolist()  # the one solve, written as solved
    assert len(summary["platform_position_m"]) == scene.space.position_size
    assert (out / "rest_profile.png").stat().st_size > 20_000 and (out / "rest.npz").exists() == npz


def test_cli_static_help_shows_an_example(capsys):
    with pytest.raises(SystemExit):
        main(["static", "--help"])
    assert "cdpr static paper-catenary-fixed --out" in capsys.readouterr().out


# --------------------------------------------------------------------------- in space


def test_a_planar_robot_written_as_a_spatial_scene_rests_where_the_planar_model_rests():
    spatial = solve_rest(scene_from_dict(PLANAR_AS_SPATIAL))
    _, planar = shipped_rest("paper-catenary-fixed")
    x, z = planar.position
    # Both are exact static equilibria of the same discrete model (the 3-D bending force of a
    # cable in a vertical plane is the planar one to 1e-12 N, tests/test_bending_3d.py); the
    # planar state is polished by Exudyn's static solver too. Measured 2.5e-12 m and 3e-10 N;
    # the bounds leave room for the Newton tolerance (1e-9 relative) and are far below the
    # 4.5 mm that bending moves the platform here and the 1e-5 m discretisation error.
    assert spatial.position == pytest.approx([x, 0.0, z], abs=1e-9)
    assert np.abs(spatial.rotation).max() < 1e-12  # a point mass does not turn
    for i in range(2):  # the joint reactions, bending shear included
        assert spatial.platform_forces[i][[0, 2]] == pytest.approx(planar.platform_forces[i], abs=1e-7)
        assert spatial.platform_forces[i][1] == pytest.approx(0.0, abs=1e-12)


def test_without_bending_the_lumped_robot_rests_within_its_discretisation_error_of_the_catenaries():
    scene = load_scene("spatial-four-cable")
    scene = replace(scene, effects=replace(scene.effects, bending=False, bending_damping=False))
    rest = solve_rest(scene)
    # tests/test_spatial_robot.py measures the lumped robot against the catenaries as n^-2,
    # 1.9e-5 m, 1.7e-5 rad and 0.016 N at 20 elements: 2.5e-5 and 0.025 N bound them.
    assert np.linalg.norm(rest.position - rest.catenary.position) < 2.5e-5
    assert np.linalg.norm(rest.rotation - rest.catenary.rotation) < 2.5e-5
    assert rest.anchor_tensions == pytest.approx(rest.catenary.tensions_at_anchor, abs=0.025)


def test_the_cogiro_scene_is_caspr_s_geometry_and_hangs_where_its_ideal_cables_put_it():
    scene = load_scene("spatial-cogiro")
    # the TOML holds CASPR's numbers (tests/data/caspr/, read by cdpr import caspr) to their 4 decimals
    caspr, _ = caspr_scene(*(Path(__file__).parent / "data" / "caspr" / f"CoGiRo_{part}.xml" for part in ("bodies", "cables")))
    assert scene.exit_points == pytest.approx(caspr.exit_points, abs=1e-12)
    assert np.asarray(scene.platform.anchors) == pytest.approx(np.asarray(caspr.platform.anchors), abs=5e-5)
    _, rest = shipped_rest("spatial-cogiro")
    ideal = caspr.trajectory.pose(0.0)[:3]  # CASPR's initial pose, its centre of mass
    # Lengths are the ideal ones less their straight stretch, so only the sag (about 15 mm
    # mid-span, which shortens each chord by ~0.1 mm) moves the platform: it rises by 1.1 mm
    # (measured); 3 mm bounds that, while a wrong anchor or exit moves it by centimetres.
    assert rest.position == pytest.approx(ideal, abs=3e-3)
    assert np.linalg.norm(rest.rotation) < 1e-3
    low, high = caspr.tension_limits.T
    assert np.all((rest.anchor_tensions > low) & (rest.anchor_tensions < high))


def test_the_ipanema_scene_is_held_from_above_and_below_at_its_design_pose():
    _, rest = shipped_rest("spatial-ipanema")
    # Fully constrained by 8 pretensioned cables (EA = 0.5 MN) whose lengths are the ideal ones
    # less their stretch: sag (a few mm over 4.7 m of a 0.012 kg/m rope at 300-480 N) hardly
    # moves the platform; measured 17 um from (0, 0, 2) m. 0.2 mm bounds it, while a flipped
    # or wrong equilibrium of the catenary start lies decimetres away.
    assert rest.position == pytest.approx([0.0, 0.0, 2.0], abs=2e-4)
    assert np.linalg.norm(rest.rotation) < 1e-4
    upper, lower = rest.platform_forces[:4], rest.platform_forces[4:]
    assert np.all(upper[:, 2] > 0.0) and np.all(lower[:, 2] < 0.0)  # pulled up and pulled down
    assert np.all(rest.anchor_tensions > 50.0)  # the pretension floor the lengths were made with
