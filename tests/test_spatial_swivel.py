"""Spatial scenes with swivel-pulley exits (issue 15): scene, catenary statics, Exudyn's static solution, runs."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import swivel_pulley_exit
from cdpr_exu.exits import Swivel
from cdpr_exu.statics.statics import catenary_platform, solve_statics
from cdpr_exu.run.rest import solve_rest
from cdpr_exu.scenes.scene import load_scene, save_scene, scene_from_dict

NAME = "spatial-four-cable-swivel"


def without_bending(scene, n_elements=None):
    """The scene without bending (the catenary's cable), optionally with another element count."""
    scene = replace(scene, effects=replace(scene.effects, bending=False, bending_damping=False))
    if n_elements is not None:
        scene = replace(scene, cables=tuple(replace(c, n_elements=n_elements) for c in scene.cables))
    return scene


def test_the_swivel_scene_loads_and_round_trips_through_toml(tmp_path):
    scene = load_scene(NAME)
    assert all(isinstance(e, Swivel) and e.radius == 0.1 for e in scene.exits) and all(e.wraps for e in scene.exits)
    assert scene.exit_points[0].tolist() == list(scene.exits[0].inlet) and [e.radius for e in scene.exits] == [0.1] * 4
    again = load_scene(save_scene(scene, tmp_path / "scene.toml"))
    assert again == scene
    # a point-exit scene: point exits written and read, no swivels
    plain = load_scene("spatial-four-cable")
    assert not any(e.wraps for e in plain.exits) and all(e["kind"] == "point" for e in plain.to_dict()["exits"])
    assert load_scene(save_scene(plain, tmp_path / "plain.toml")) == plain


def _with_exit(change):
    data = load_scene(NAME).to_dict()
    change(data["exits"][0])
    return data


@pytest.mark.parametrize("change, field", [
    (lambda e: e.update(radius=-0.1), r"exits\[0\]\.radius"),
    (lambda e: e.update(groove_radius=0.2), r"exits\[0\]\.groove_radius"),
    (lambda e: e.update(contact_stiffness=0.0), r"exits\[0\]\.contact_stiffness"),
    (lambda e: e.update(swivel_inertia=float("nan")), r"exits\[0\]\.swivel_inertia"),
    (lambda e: e.update(bearing_damping=-1.0), r"exits\[0\]\.bearing_damping"),
    (lambda e: e.update(winch_line=0.0), r"exits\[0\]\.winch_line"),
    (lambda e: e.update(inlet=[1.0, 2.0]), r"exits\[0\]\.inlet"),
    (lambda e: e.update(kind="capstan"), r"exits\[0\]\.kind"),
    (lambda e: e.update(sheave=1.0), r"exits\[0\]"),
    (lambda e: e.update(radius=0.04), r"cables\[0\]\.n_elements"),  # elements longer than half the radius
])
def test_bad_swivel_fields_are_refused_naming_the_field(change, field):
    with pytest.raises(SceneError, match=field):
        scene_from_dict(_with_exit(change))


def test_the_catenary_statics_over_swivel_pulleys_balance_and_point_each_pulley_at_its_anchor():
    scene = load_scene(NAME)
    equilibrium = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    weight = scene.platform.mass * scene.gravity
    assert np.abs(equilibrium.net_wrench[:3]).max() < 1e-9 * weight
    for cable, swivel in zip(equilibrium.cables, scene.exits):
        ideal = swivel_pulley_exit(swivel.inlet, swivel.radius, cable.anchor_point)
        # the suspended part sags (its end at the disc is 5.1 degrees steeper than the chord,
        # measured), so it leaves the disc further round than a straight cable
        assert ideal.wrap_angle < cable.wrap_angle < ideal.wrap_angle + 0.1
        # the tangent point lies on the disc in the vertical plane through the axis and the anchor
        centre = np.asarray(swivel.inlet) + swivel.radius * cable.horizontal_direction
        assert np.linalg.norm(cable.exit_point - centre) == pytest.approx(swivel.radius, abs=1e-12)
        assert np.cross(cable.exit_point - swivel.inlet, cable.anchor_point - swivel.inlet)[2] == pytest.approx(
            0.0, abs=1e-12)


def test_exudyn_s_static_hang_converges_to_the_catenary_statics_as_the_elements_shrink():
    rests = [solve_rest(without_bending(load_scene(NAME), n)) for n in (48, 96)]
    errors = [np.linalg.norm(r.position - r.catenary.position) for r in rests]
    # Measured 4.90 / 1.17 / 0.34 mm at 48 / 96 / 192 elements (the chords of the wrap are
    # shorter than its arc, r_p theta^3 / 24 each, and the nodes sink T l_e / (r_p k_p) into
    # the groove): about n^-2. The bounds sit 20 % above those numbers.
    assert errors[0] < 5.9e-3 and errors[1] < 1.4e-3
    assert errors[0] / errors[1] > 3.0  # second order (4.2 measured)
    for rest in rests:  # tensions at the anchor: the same order
        assert rest.anchor_tensions == pytest.approx(rest.catenary.tensions_at_anchor, abs=0.5)


def test_a_symmetric_robot_over_swivel_pulleys_hangs_symmetric():
    scene = without_bending(load_scene(NAME))
    rest = solve_rest(scene)
    # four equal cables from the corners of a square: on the axis, equal tensions, each
    # pulley turned to its anchor (-135, -45, 45, 135 degrees)
    assert np.abs(rest.position[:2]).max() < 1e-9
    assert np.ptp(rest.anchor_tensions) < 1e-6 * rest.anchor_tensions.max()
    assert rest.swivel_angles == pytest.approx(np.radians([-135.0, -45.0, 45.0, 135.0]), abs=1e-9)
    weight = scene.platform.mass * scene.gravity
    assert rest.platform_forces.sum(axis=0) == pytest.approx([0.0, 0.0, weight], abs=1e-8 * weight)


def test_spatial_scenes_honour_the_paper_mass_lumping():
    import exudyn as exu

    from cdpr_exu.builder.robot_3d import build_spatial_robot, scene_chain_spec

    scene = load_scene("spatial-four-cable")
    paper = replace(scene, cables=tuple(replace(c, mass_lumping="paper") for c in scene.cables))
    for chosen in (scene, paper):
        mbs = exu.SystemContainer().AddSystem()
        items = build_spatial_robot(mbs, catenary_platform(chosen), chosen.unstrained_lengths, scene_chain_spec(chosen))
        cable = chosen.cables[0]
        # the planar cable's own lumping (CableSpec.node_masses), exit node first
        assert items.node_masses[0] == pytest.approx(cable.node_masses(), rel=1e-12)
    with pytest.raises(SceneError, match=r"cables\[1\]\.mass_lumping"):
        replace(scene, cables=(scene.cables[0], replace(scene.cables[1], mass_lumping="paper"), *scene.cables[2:]))


@pytest.fixture(scope="module")
def pushed_swivel_robot():
    """spatial-four-cable-swivel settled (with its damping), then axial damping off and the platform (and the cable
    ends on it) pushed along x at 0.2 m/s: the scenario of the 'wrong energy record'.
    Returns (mbs, items, energy at rest [J], energy after the push [J])."""
    import exudyn as exu

    from cdpr_exu.builder.robot_3d import build_spatial_robot, robot_energy, scene_chain_spec
    from cdpr_exu.run.settle import settle

    scene = load_scene(NAME)
    scene = replace(scene, effects=replace(scene.effects, bending_damping=False))
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, catenary_platform(scene), scene.unstrained_lengths,
                                scene_chain_spec(scene, tension_only=False), exits=scene.exits)
    mbs.Assemble()
    settle(mbs, items)
    for chain in items.chains:  # axial damping off: nothing dissipates but the integrator
        for spring in chain.springs:
            mbs.SetObjectParameter(spring, "damping", 0.0)
    rest = robot_energy(mbs, items, current=False)
    velocities = np.zeros(len(mbs.systemData.GetODE2Coordinates_t(exu.ConfigurationType.Initial)))
    for node in [items.platform_node] + [chain.nodes[-1] for chain in items.chains]:
        velocities[mbs.GetNodeODE2Index(node)] = 0.2
    mbs.systemData.SetODE2Coordinates_t(velocities, exu.ConfigurationType.Initial)
    return mbs, items, rest, robot_energy(mbs, items, current=False)


def _pushed_run(pushed, step, spectral_radius, modified_newton, end_time=0.05):
    from cdpr_exu.run.settle import dynamic_settings
    from cdpr_exu.run.dynamics import run_dynamic

    mbs, items, _, _ = pushed
    settings = dynamic_settings(end_time, step, spectral_radius, tolerance=1e-6 if modified_newton else 1e-8)
    settings.timeIntegration.newton.useModifiedNewton = modified_newton
    settings.timeIntegration.newton.modifiedNewtonJacUpdatePerStep = True
    settings.timeIntegration.generalizedAlpha.computeInitialAccelerations = False
    return run_dynamic(mbs, items, end_time, step, record_energy=True, settings=settings).energy


def test_the_settled_swivel_robot_starts_at_rest_so_a_push_records_only_the_integrator_s_losses(pushed_swivel_robot):
    _, _, rest, pushed = pushed_swivel_robot
    # the push: the 5 kg platform and the four anchor nodes (half a 5 cm element of 0.35 kg/m each) at 0.2 m/s
    assert pushed - rest == pytest.approx(0.5 * (5.0 + 4 * 0.5 * 0.35 * 0.05) * 0.2**2, rel=1e-9)
    # The scene's integrator (spectral radius 0, modified Newton). Before the settle ended in
    # Exudyn's static equilibrium, the Kelvin-Voigt creep (d_n / E = 1 s) left the robot
    # 8.6 mm and 6.7 J above it, and the first step lost 5.1 J of that (measured): now it
    # loses 3.2 mJ, the numerical damping of the push's fast modes (measured at 1e-3 s).
    energy = _pushed_run(pushed_swivel_robot, 1e-3, 0.0, True, end_time=0.01)
    assert energy[0] == pytest.approx(pushed, abs=1e-12)
    assert -1e-2 < energy[1] - energy[0] < 0.0
    assert np.all(np.diff(energy) < 1e-6)  # no step gains energy (-7.9e-6 J the largest change measured)


def test_without_damping_the_energy_over_swivel_pulleys_is_bounded_and_its_first_step_error_third_order(
        pushed_swivel_robot):
    # Spectral radius 1, full Newton, no damping anywhere (the bearing's 1e-3 N m s takes
    # below 1e-7 J here). Measured over 0.05 s: largest |E - E0| 1.31 / 1.79 mJ at steps
    # 2e-3 / 1e-3 s, of a 0.1 J push; the error comes in single steps where a node enters or
    # leaves the groove, about k_p (v h)^2 / 8 each (the contact force has a kink there),
    # so over 0.2 s it is 9.4 / 62 / 42 / 1.5 / 0.37 mJ at 2e-3 / 1e-3 / 5e-4 / 2.5e-4 /
    # 1.25e-4 s: second order (ratio 4.0) only once omega h < 2 for a node on the contact
    # spring (omega = sqrt(k_p / m) = 7600 rad/s). Between such events the scheme conserves
    # energy to second order: the first step's error (no contact change) is 1.4e-6 / 1.9e-7 J.
    errors, first = [], []
    for step in (2e-3, 1e-3):
        energy = _pushed_run(pushed_swivel_robot, step, 1.0, False)
        errors.append(np.abs(energy - energy[0]).max())
        first.append(abs(energy[1] - energy[0]))
    assert max(errors) < 3e-3  # bounded: 1.8 mJ measured
    assert first[0] < 3e-6 and first[0] / first[1] > 5.0  # local error O(h^3): 7.3 measured


def test_the_inverse_statics_over_swivel_pulleys_give_lengths_whose_catenaries_hold_the_pose():
    from cdpr_exu.statics.statics import solve_inverse_statics

    scene = load_scene(NAME)
    platform, lengths = catenary_platform(scene), scene.unstrained_lengths
    rest = solve_statics(platform, lengths)
    tensions = np.array([c.catenary.horizontal_tension for c in rest.cables])
    # at the rest pose with the rest tensions: the scene's lengths (8.9e-16 m measured)
    back = solve_inverse_statics(platform, rest.position, initial_guess=tensions)
    assert back.unstrained_lengths == pytest.approx(lengths, abs=1e-12)
    # off the rest pose (an indeterminate robot: tensions nearest the rest ones); the forward statics of
    # the inverse lengths put the platform back there (2e-14 m measured), the wraps included
    pose = rest.position + [0.1, -0.05, 0.08]
    inverse = solve_inverse_statics(platform, pose, initial_guess=tensions)
    forward = solve_statics(platform, inverse.unstrained_lengths)
    assert forward.position == pytest.approx(pose, abs=1e-10)
    forces = np.array([c.force_on_platform for c in inverse.cables])
    assert np.abs(forces.sum(axis=0) - [0.0, 0.0, scene.platform.mass * scene.gravity]).max() < 1e-8


def test_a_swivel_robot_starts_on_its_chain_statics_and_the_dynamic_settle_is_the_fallback():
    import exudyn as exu

    from cdpr_exu.builder.robot_3d import build_spatial_robot, scene_chain_spec
    from cdpr_exu.run.settle import start_at_rest

    scene = load_scene(NAME)  # bending on; spring elements, as cdpr static builds it

    def built():
        mbs = exu.SystemContainer().AddSystem()
        items = build_spatial_robot(mbs, catenary_platform(scene), scene.unstrained_lengths,
                                    scene_chain_spec(scene, tension_only=False), exits=scene.exits)
        mbs.Assemble()
        return mbs, items

    mbs, items = built()
    start = start_at_rest(mbs, items)
    # Exudyn's static solver, started on the chain statics' equilibrium, converges where it stands
    # (no coordinate moved by more than 4e-16, measured)
    assert start.method == "chain statics" and start.polish_shift < 1e-12
    fallback_mbs, fallback_items = built()
    with pytest.warns(RuntimeWarning, match="dynamic settle"):
        fallback = start_at_rest(fallback_mbs, fallback_items, max_iterations=1)  # the chain statics fail
    assert fallback.method == "dynamic settle" and fallback.statics is None
    # both end in Exudyn's static equilibrium of the same model (its tolerance 1e-9): 1.2e-11 apart, measured
    states = [np.asarray(m.systemData.GetODE2Coordinates(exu.ConfigurationType.Initial)) for m in (mbs, fallback_mbs)]
    assert np.abs(states[0] - states[1]).max() < 1e-9


def test_a_short_run_over_swivel_pulleys_starts_at_rest_and_follows_the_reference():
    from cdpr_exu.run.simulate import simulate

    # the shipped scene, bending on: its start, the chain statics' equilibrium, takes 0.07 s of CPU time
    # (the dynamic settle took 15 s, benchmarks/results/swivel_start.md)
    scene = load_scene(NAME)
    scene = replace(scene, solver=replace(scene.solver, end_time=0.3))
    result = simulate(scene)
    # The robot starts at rest on the axis, where the reference starts (z = -0.842 m in the scene,
    # -0.842011 m the lumped robot's rest), and tracks the ramp's first 0.3 s
    assert np.abs(result.pose[0, :2]).max() < 1e-9  # symmetric rest on the axis
    assert abs(result.pose[0, 2] - result.reference[0, 2]) < 2e-5  # 11 um measured
    moved = (result.pose[:, :3] - result.pose[0, :3]) - (result.reference[:, :3] - result.reference[0, :3])
    assert np.linalg.norm(moved, axis=1).max() < 5e-4  # 0.24 mm measured
    assert min(t.min() for t in result.tensions) > 15.0  # every element taut (21.0 N measured)


def test_the_catenary_statics_find_a_small_swivel_robot_whose_straight_start_lay_beyond_reach():
    """The swivel scene shrunk to a 1 m x 1 m frame with 1 m cables: the starting guess of
    the statics took each cable straight from its inlet, 1 m long, while over the disc
    (wrapped 2.41 rad round r_p = 0.1 m) only 0.76 m hang free, and the statics refused
    from there ("span beyond the reach"). From the start on wrapped straight cables it
    balances the weight to round-off, symmetric, where the lumped robot (48 elements, no
    bending) rests: measured 0.61 mm apart (0.17 mm at 96 elements: second order, the wrap's
    chords as above). Bound: 0.8 mm."""
    data = without_bending(load_scene(NAME), 48).to_dict()
    for exit_ in data["exits"]:
        exit_["inlet"] = [0.5 * np.sign(exit_["inlet"][0]), 0.5 * np.sign(exit_["inlet"][1]), 0.0]
    for cable in data["cables"]:
        cable["unstrained_length"] = 1.0
    scene = scene_from_dict(data)
    equilibrium = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    weight = scene.platform.mass * scene.gravity
    assert np.abs(equilibrium.net_wrench[:3]).max() < 1e-9 * weight
    assert np.abs(equilibrium.position[:2]).max() < 1e-9
    rest = solve_rest(scene)
    assert np.linalg.norm(rest.position - equilibrium.position) < 8e-4


def stiff_swivel(youngs_modulus, mass=16.8):
    """The shipped swivel robot with stiffer cables and a heavier platform (issue 23.3's scene at 2.4e11 Pa)."""
    scene = load_scene(NAME)
    return replace(scene, cables=tuple(replace(c, youngs_modulus=youngs_modulus) for c in scene.cables),
                   platform=replace(scene.platform, mass=mass))


def _cdpr(*args):
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "cdpr_exu.cli", *args], capture_output=True, text=True, timeout=600)


def test_a_static_answer_above_the_pulleys_fails_with_its_cause_instead_of_exiting_0(tmp_path):
    """Issue 23.3: at E = 2.4e11 Pa (a solid steel rod's J, bending length sqrt(E J / T) = 1.08 m at the
    catenaries' 102 N against 0.1 m pulleys) the lumped robot's equilibrium stands the platform 0.64 m
    above its pulley inlets, 1.50 m from its catenaries' answer (-0.87 m), with elements pushing (-65 N);
    `cdpr static` exited 0 with a note. It is the bending model's equilibrium, not a start's accident
    (tension-only chain statics give 0.63 m too): refused, exit 3, with the cause and the state."""
    import json

    from cdpr_exu.scenes.scene import save_scene

    path = save_scene(stiff_swivel(2.4e11), tmp_path / "stiff.toml")
    out = tmp_path / "static"
    done = _cdpr("static", str(path), "--out", str(out))
    assert done.returncode == 3, done.stderr
    for words in ("every anchor is at or above the top of its exit", "exits[0] up to z = 0.1 m",
                  "bending length sqrt(E J / T) = 1.08 m", "11 times the pulleys' radius", "youngs_modulus"):
        assert words in done.stderr, words
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"].startswith("failed: no rest of a cable robot")
    # the state it refused, for a look: 0.636 m up, 1.504 m from the catenaries (measured)
    assert summary["last_state"]["platform_position_m"][2] == pytest.approx(0.636, abs=0.01)
    assert summary["last_state"]["lumped_minus_catenary_position_m"] == pytest.approx(1.504, abs=0.01)


def test_a_static_answer_far_from_its_catenaries_warns_in_the_summary_and_on_the_console(tmp_path):
    """E = 1e10 Pa: the platform hangs below its pulleys but 132 mm (5.5 % of the 2.4 m cables, measured)
    from its catenaries' answer, the bending's doing; the shipped robot's 22 mm (0.9 %) is not flagged."""
    import json

    from cdpr_exu.run.rest import FAR_FROM_CATENARY
    from cdpr_exu.scenes.scene import save_scene

    shipped = solve_rest(load_scene(NAME))
    assert shipped.catenary_distance < 0.2 * FAR_FROM_CATENARY * 2.4 and shipped.warnings == ()  # 22 mm of 120
    path = save_scene(stiff_swivel(1e10), tmp_path / "stiffer.toml")
    out = tmp_path / "static"
    done = _cdpr("static", str(path), "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "cdpr: warning: the lumped robot rests 132 mm from its elastic catenaries' answer, more than 5 %" \
        in done.stderr, done.stderr
    warnings = json.loads((out / "summary.json").read_text())["warnings"]
    assert len(warnings) == 1 and "bending length sqrt(E J / T) = 0.22 m" in warnings[0]


def test_a_run_does_not_start_from_a_rest_above_the_pulleys():
    """The run over swivel pulleys starts from the chain statics' rest: at 2.4e11 Pa that stood the
    platform 0.63 m above the inlets, and the run reported `completed`."""
    from cdpr_exu.core.errors import SolverFailure
    from cdpr_exu.run.simulate import simulate

    scene = stiff_swivel(2.4e11)
    scene = replace(scene, solver=replace(scene.solver, end_time=0.05))
    with pytest.raises(SolverFailure, match=r"failed at t = 0\.0000 s.*cannot start from the robot's rest: .* at z = 0\.63\d+ m .*above the top"):
        simulate(scene)


def test_a_winch_line_shorter_than_its_margin_is_refused_in_millimetres_with_what_to_give():
    """Issue 23.9: a 0.1 mm winch_line was refused as "paid out by 0.0000 m ... more than
    exits[0].winch_line = 0.0001 m less two elements holds"."""
    from cdpr_exu.core.errors import UnreachableError
    from cdpr_exu.statics.workspace import check_reference

    data = load_scene(NAME).to_dict()
    for entry in data["exits"]:
        entry["winch_line"] = 1e-4
    with pytest.raises(UnreachableError) as caught:
        check_reference(scene_from_dict(data))
    message = str(caught.value)
    for words in ("exits[0].winch_line = 0.1 mm less two elements (2 x 50 mm", "leaves -99.9 mm",
                  "give exits[0].winch_line = 100 mm or more"):
        assert words in message, message
    assert "0.0000" not in message


def test_an_anchor_on_a_swivel_axis_says_what_to_change_in_the_scene():
    """Issue 23.9: the refusal asked for `azimuth_hint`, which no scene has."""
    from cdpr_exu.core.errors import UnreachableError
    from cdpr_exu.statics.workspace import check_reference

    data = load_scene(NAME).to_dict()
    data["trajectory"] = {"kind": "hold", "pose": [1.5, 1.5, -0.5, 0.0, 0.0, 0.0]}  # below the first inlet
    with pytest.raises(UnreachableError) as caught:
        check_reference(scene_from_dict(data))
    message = str(caught.value)
    assert "start the reference (the scene's trajectory) with every anchor off the vertical axis" in message, message
    assert "give azimuth_hint" not in message


def test_a_halved_step_over_swivel_pulleys_doubles_again_sooner_and_planar_pulleys_keep_exudyns_recovery():
    # spatial-four-cable-swivel's failed steps are single kinks at an inlet and the halved steps after them took as
    # many Newton iterations as full ones (run/solver.py STEP_RECOVERY); planar pulley runs are not measured
    from cdpr_exu.run.solver import STEP_RECOVERY, solver_settings
    from cdpr_exu.space import SPACE

    def recovery(name):
        ti = solver_settings(load_scene(name)).timeIntegration
        return ti.adaptiveStepRecoverySteps, ti.adaptiveStepRecoveryIterations

    assert recovery("spatial-four-cable-swivel") == STEP_RECOVERY[SPACE] == (3, 5)
    assert recovery("paper-circle") == recovery("spatial-cogiro") == (10, 7)
