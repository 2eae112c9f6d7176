"""Spatial scenes in TOML (cdpr_exu.scenes.scene with dimension = 3) and their static mode (cdpr_exu.run.spatial_rest),
real solver."""

import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.physics import cogiro
from cdpr_exu.run.rest import solve_rest
from cdpr_exu.run.spatial_rest import solve_spatial_rest
from cdpr_exu.scenes.scene import load_scene, scene_from_dict, shipped_scenes

#: The paper's catenary scene with fixed cable ends, written as a spatial scene in the
#: vertical x-z plane (y = 0): the same cables, elements, masses and bending.
PLANAR_AS_SPATIAL = {
    "name": "paper-catenary-fixed-3d", "dimension": 3, "gravity": 9.8,
    "cable": {"unstrained_length": 2.4748737341529163, "radius": 0.005, "linear_density": 0.35,
              "youngs_modulus": 1.0e9, "damping_constant": 1.0e9, "n_elements": 15},
    "cables": [{}, {}],
    "exits": [{"point": [-1.75, 0.0, 0.0]}, {"point": [1.75, 0.0, 0.0]}],
    "platform": {"mass": 1.0, "anchors": [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]},
}


def _cdpr(*args):
    return subprocess.run([sys.executable, "-m", "cdpr_exu.cli", *args], capture_output=True, text=True, timeout=300)


def test_the_one_loader_loads_the_shipped_spatial_scenes_beside_the_planar_ones():
    assert "spatial-four-cable" in shipped_scenes() and "paper-circle" in shipped_scenes()
    scene = load_scene("spatial-four-cable")
    assert scene.dimension == 3 and scene.n_cables == 4 and not scene.platform.is_point_mass
    assert scene.space.pose_size == 6 and load_scene("paper-circle").space.pose_size == 3


def test_run_and_the_accuracy_study_need_a_trajectory_on_a_spatial_scene(tmp_path):
    done = _cdpr("study", "accuracy", "spatial-four-cable", "--out", str(tmp_path / "study"))
    assert done.returncode == 2
    assert "no [trajectory]" in done.stderr and "cdpr static" in done.stderr
    assert not (tmp_path / "study").exists()  # refused before any run
    done = _cdpr("run", "spatial-four-cable")  # a static scene: no reference to follow
    assert done.returncode == 2 and "no [trajectory]" in done.stderr


def test_a_planar_robot_written_as_a_spatial_scene_rests_where_the_planar_model_rests():
    spatial = solve_spatial_rest(scene_from_dict(PLANAR_AS_SPATIAL))
    planar = solve_rest(load_scene("paper-catenary-fixed"))
    x, z = planar.platform_position_m
    # Both are exact static equilibria of the same discrete model (the 3-D bending force of a
    # cable in a vertical plane is the planar one to 1e-12 N, tests/test_bending_3d.py); the
    # planar state is polished by Exudyn's static solver too. Measured 2.5e-12 m and 3e-10 N;
    # the bounds leave room for the Newton tolerance (1e-9 relative) and are far below the
    # 4.5 mm that bending moves the platform here and the 1e-5 m discretisation error.
    assert spatial.position == pytest.approx([x, 0.0, z], abs=1e-9)
    assert np.abs(spatial.rotation_vector).max() < 1e-12  # a point mass does not turn
    for i in range(2):  # the joint reactions, bending shear included
        assert spatial.forces_on_platform[i][[0, 2]] == pytest.approx(planar.platform_forces_N[i], abs=1e-7)
        assert spatial.forces_on_platform[i][1] == pytest.approx(0.0, abs=1e-12)


def test_without_bending_the_lumped_robot_rests_within_its_discretisation_error_of_the_catenaries():
    scene = load_scene("spatial-four-cable")
    scene = replace(scene, effects=replace(scene.effects, bending=False, bending_damping=False))
    rest = solve_spatial_rest(scene)
    # tests/test_spatial_robot.py measures the lumped robot against the catenaries as n^-2,
    # 1.9e-5 m, 1.7e-5 rad and 0.016 N at 20 elements: 2.5e-5 and 0.025 N bound them.
    assert np.linalg.norm(rest.position - rest.catenary.position) < 2.5e-5
    assert np.linalg.norm(rest.rotation_vector - rest.catenary.rotation) < 2.5e-5
    assert rest.tensions_at_anchor == pytest.approx(rest.catenary.tensions_at_anchor, abs=0.025)


@pytest.mark.parametrize("name", ["spatial-four-cable", "spatial-cogiro", "spatial-ipanema"])
def test_the_cables_hold_the_platform_in_force_and_moment_balance(name):
    scene = load_scene(name)
    rest = solve_spatial_rest(scene)
    weight = scene.platform.mass * scene.gravity
    forces = rest.forces_on_platform
    arms = np.asarray(scene.platform.anchors) @ rest.rotation.T
    # Exudyn's static solver converges to 1e-9 (relative); the penalty joints move nothing
    # in the balance: 1e-8 of the weight (49 N, 893 N and 245 N).
    assert forces.sum(axis=0) == pytest.approx([0.0, 0.0, weight], abs=1e-8 * weight)
    assert np.cross(arms, forces).sum(axis=0) == pytest.approx(np.zeros(3), abs=1e-8 * weight)
    assert np.all(rest.tensions_at_anchor > 0.0)


def test_the_cogiro_scene_is_caspr_s_geometry_and_hangs_where_its_ideal_cables_put_it():
    scene = load_scene("spatial-cogiro")
    # the TOML holds CASPR's numbers (cdpr_exu/physics/cogiro.py) to their 4 decimals
    assert scene.exit_points == pytest.approx(cogiro.EXIT_POINTS, abs=1e-12)
    assert np.asarray(scene.platform.anchors) == pytest.approx(cogiro.ANCHORS - cogiro.CENTER_OF_MASS, abs=5e-5)
    rest = solve_spatial_rest(scene)
    ideal = cogiro.INITIAL_POSE[:3] + cogiro.CENTER_OF_MASS
    # Lengths are the ideal ones less their straight stretch, so only the sag (about 15 mm
    # mid-span, which shortens each chord by ~0.1 mm) moves the platform: it rises by 1.1 mm
    # (measured); 3 mm bounds that, while a wrong anchor or exit moves it by centimetres.
    assert rest.position == pytest.approx(ideal, abs=3e-3)
    assert np.linalg.norm(rest.rotation_vector) < 1e-3
    assert np.all((rest.tensions_at_anchor > cogiro.MIN_TENSION) & (rest.tensions_at_anchor < cogiro.MAX_TENSION))


def test_cdpr_static_on_a_spatial_scene_prints_the_pose_and_writes_a_strict_summary(tmp_path):
    out = tmp_path / "static"
    done = _cdpr("static", "spatial-four-cable", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "platform at x =" in done.stdout and "rotation vector" in done.stdout
    summary = json.loads((out / "summary.json").read_text(), parse_constant=lambda c: pytest.fail(c))
    assert len(summary["platform_position_m"]) == 3 and len(summary["platform_rotation_vector_rad"]) == 3
    assert summary["dimension"] == 3 and (out / "rest_profile.png").stat().st_size > 20_000


@pytest.mark.parametrize("change, field", [
    (lambda d: d.update(exits=d["exits"][:1]), "exits"),
    (lambda d: d.update(effects={"preset": "ideal"}), "effects.preset"),
    (lambda d: d.update(cables=[{}, {"n_elements": 20}]), "cables\\[1\\].n_elements"),
    (lambda d: d.update(dimension=4), "dimension"),
    (lambda d: d.pop("exits"), "exits"),
    (lambda d: d.update(exits=[{"point": [0.0, 0.0, 0.0]}, {"point": [0.0, 0.0, 0.0]}]), "exit_point"),
    (lambda d: d.update(exits=[{"kind": "pulley", "center": [0.0, 0.0]}] * 2), "no such exit in a spatial scene"),
    (lambda d: d["platform"].update(initial_pose=[0.0] * 6), "platform.initial_pose"),
    (lambda d: d["platform"].update(anchors=[[0.0, 0.0, 0.0], [0.0, float("nan"), 0.0]]), "platform.anchors\\[1\\]"),
    (lambda d: d["platform"].update(mass=-1.0), "platform.mass"),
    (lambda d: d["cable"].update(radius=-0.005), "cables\\[0\\].radius"),
])
def test_a_bad_spatial_scene_is_refused_naming_the_field(change, field):
    data = json.loads(json.dumps(PLANAR_AS_SPATIAL))
    change(data)
    with pytest.raises(SceneError, match=field):
        scene_from_dict(data)


def test_the_ipanema_scene_is_held_from_above_and_below_at_its_design_pose():
    scene = load_scene("spatial-ipanema")
    rest = solve_spatial_rest(scene)
    # Fully constrained by 8 pretensioned cables (EA = 0.5 MN) whose lengths are the ideal ones
    # less their stretch: sag (a few mm over 4.7 m of a 0.012 kg/m rope at 300-480 N) hardly
    # moves the platform; measured 17 um from (0, 0, 2) m. 0.2 mm bounds it, while a flipped
    # or wrong equilibrium of the catenary start lies decimetres away.
    assert rest.position == pytest.approx([0.0, 0.0, 2.0], abs=2e-4)
    assert np.linalg.norm(rest.rotation_vector) < 1e-4
    upper, lower = rest.forces_on_platform[:4], rest.forces_on_platform[4:]
    assert np.all(upper[:, 2] > 0.0) and np.all(lower[:, 2] < 0.0)  # pulled up and pulled down
    assert np.all(rest.tensions_at_anchor > 50.0)  # the pretension floor the lengths were made with



def test_the_static_mode_reports_every_element_taut_on_the_shipped_robots():
    for name in ("spatial-four-cable", "spatial-cogiro", "spatial-ipanema"):
        summary = solve_spatial_rest(load_scene(name)).summary()
        # the lowest of all elements (4 x 20 or 8 x 20): the four-cable robot's slackest cable
        # still carries about 10 N; nothing is compressed
        assert summary["min_element_tension_N"] > 5.0 and not summary["elements_pushed"], name


def test_a_spatial_scene_gets_the_planar_bending_damping_constant_only_with_effects_bending_damping():
    """c_theta = d_n J / l_e on every joint (the planar CableSpec.bending_damping); without
    effects.bending_damping the chains have no dampers (and no cost for them)."""
    import exudyn as exu

    from cdpr_exu.builder.robot_3d import build_spatial_robot, scene_chain_spec
    from cdpr_exu.statics.statics import catenary_platform

    scene = load_scene("spatial-four-cable")
    for damped in (True, False):
        changed = replace(scene, effects=replace(scene.effects, bending_damping=damped))
        mbs = exu.SystemContainer().AddSystem()
        items = build_spatial_robot(mbs, catenary_platform(changed), changed.unstrained_lengths, scene_chain_spec(changed))
        for cable, chain in zip(changed.cables, items.chains):
            if damped:
                assert chain.bending_damping == pytest.approx(np.full(len(chain.joints), cable.bending_damping),
                                                              rel=1e-12)
            else:
                assert chain.bending_damping is None and chain.bending_stiffness is not None


def test_a_misspelt_scene_name_lists_every_shipped_scene_and_the_likeliest_first(capsys):
    """Issue 23.7: `cdpr run spatial-cogiroo` listed only the planar scenes as alternatives."""
    from cdpr_exu.cli import main
    from cdpr_exu.scenes.scene import shipped_scenes

    assert main(["run", "spatial-cogiroo"]) == 2
    message = capsys.readouterr().err
    assert "no scene named 'spatial-cogiroo'; did you mean 'spatial-cogiro'? shipped scenes:" in message, message
    for name in shipped_scenes():
        assert name in message, name
    for misspelt, meant in (("paper-circel", "'paper-circle' or 'paper-circle-slow'"), ("ipanema", "'spatial-ipanema'")):
        with pytest.raises(SceneError, match=f"did you mean {meant}\\?"):
            load_scene(misspelt)
    with pytest.raises(SceneError, match="did you mean 'spatial-four-cable' or 'spatial-four-cable-swivel'"):
        load_scene("spatial-four")
