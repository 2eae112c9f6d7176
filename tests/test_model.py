"""Tests of the Exudyn model the builder makes (cdpr_exu.builder.model and its builders).

Sections: what items the builder adds; statics of cables at rest on the real solver
(weight balance, end reactions, Hooke's law); bad input refused before any simulation.
"""

from __future__ import annotations

import dataclasses
import math

import exudyn as exu
import numpy as np
import pytest

from cdpr_exu.builder.cable import element_tensions
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.builder.model import build_model, contact_candidates
from cdpr_exu.exits import Pulley
from cdpr_exu.scenes.scene import CableSpec, Effects, PlatformSpec, Scene, SolverSpec, load_scene
from cdpr_exu.run.simulate import simulate, solver_settings
from cdpr_exu.scenes.trajectories import CircleTrajectory


def settle(scene):
    """Build ``scene`` and integrate it to rest (its end time); returns the Model.

    Uses the scene's solver settings (meant: ``conftest.settling_solver``) with one
    change: Exudyn's initial-acceleration computation is off. At t = 0 the springs are
    at their unstrained length, so the consistent initial acceleration of every free
    node is -g; but the Kelvin-Voigt damping (c_i / m_i ~ 4e6 1/s) cuts it off within
    a microsecond. Generalized-alpha with rho_inf = 0 (beta = 1, gamma = 1.5) carries
    -g into its first 0.2 s step and lifts the nodes by ~6 cm (13-27 % strain, which
    ``simulate``'s monitor rightly refuses); starting from a0 = 0 the largest strain
    on the way to rest is the static one (1.6e-4) for a hanging cable, 0.9 % for the
    sagging V. The state at rest does not depend on this.
    """
    model = build_model(scene)
    settings = solver_settings(scene)
    settings.timeIntegration.generalizedAlpha.computeInitialAccelerations = False
    model.mbs.SolveDynamic(settings)
    return model


def cable_state(model, i):
    """Node positions and velocities (x, z) of cable i now, each shape (n + 1, 2)."""
    data = model.mbs.systemData
    idx = model.coordinate_indices()[f"cable_{i}"]
    reference = data.GetODE2Coordinates(exu.ConfigurationType.Reference)
    return reference[idx] + data.GetODE2Coordinates()[idx], data.GetODE2Coordinates_t()[idx]


def settled_tensions(scene):
    """Settle ``scene``; element axial forces and node positions of every cable at rest."""
    model = settle(scene)
    out = []
    for i, cable in enumerate(scene.cables):
        positions, velocities = cable_state(model, i)
        out.append((element_tensions(cable, positions, velocities, scene.effects), positions))
    return model, out


def end_forces_on_cable(model, i):
    """Forces (x, z) [N] the winch and the platform joint exert on cable i's end nodes.

    Exudyn's ``ObjectConnectorCoordinate`` reports its Lagrange multiplier lambda; the
    force on the constrained node coordinate (its marker 1) is -lambda.
    ``ObjectJointRevolute2D`` reports the force on its marker 0, the platform anchor;
    the cable's last node (marker 1) receives the opposite force. These conventions
    are pinned by ``test_winch_and_joint_reactions_hold_a_hanging_cable``.

    Returns
    -------
    top : ndarray, shape (2,)
        On node 0, from the winch constraints.
    bottom : ndarray, shape (2,)
        On node n, from the platform joint.
    """
    mbs, winch = model.mbs, model.winches[i]
    force = exu.OutputVariableType.Force
    top = -np.array([mbs.GetObjectOutput(winch.horizontal, force), mbs.GetObjectOutput(winch.vertical, force)])
    on_platform = np.asarray(mbs.GetObjectOutput(model.platform.joints[i], force))[:2]
    return top, -on_platform


# ============================================================================ items


@pytest.fixture(scope="module")
def paper_model():
    """The paper scene built as the paper published it (spring-dampers that can push)."""
    return build_model(load_scene("paper-circle").with_changes(effects=Effects.from_preset("paper")))


def test_paper_scene_has_a_mass_point_per_node_and_a_spring_damper_per_element(paper_model):
    counts = paper_model.item_counts()
    assert counts["mass_points"] == 2 * 16
    assert counts["axial_spring_dampers"] == 2 * 15
    assert counts["gravity_loads"] == 2 * 16 + 1  # every node and the platform
    assert counts["winch_constraints"] == 2 * 2
    assert counts["platform_joints"] == 2


def test_paper_scene_bends_at_every_interior_node_in_one_object(paper_model):
    counts = paper_model.item_counts()
    assert counts["cable_force_objects"] == 1
    assert counts["bending_joints"] == 2 * 14
    assert counts["slack_elements"] == 0  # the paper's elements push as well as pull
    joints = paper_model.cable_forces.joints
    # consecutive triplets (b - 1, b, b + 1), never spanning two cables (nodes 0-15 and 16-31)
    assert np.all(np.diff(joints, axis=1) == 1)
    assert not np.any((joints[:, 0] <= 15) & (joints[:, 2] >= 16))


def test_pulley_contacts_only_on_nodes_that_can_reach_the_pulley(paper_model):
    counts = paper_model.item_counts()
    assert 0 < counts["pulley_contacts"] < 2 * 16
    contact = paper_model.cable_forces.node_contact  # all of them in the cables' object, Exudyn's law frozen
    assert contact.nodes.size == counts["pulley_contacts"] and contact.band == 0.0
    for i, nodes in enumerate(paper_model.contact_nodes):
        assert 0 not in nodes  # the winch node's motion is prescribed
        assert 15 not in nodes  # the anchor node stays over 1 m below the pulley centre
        np.testing.assert_array_equal(nodes, contact_candidates(paper_model.scene, i))


def test_catenary_preset_adds_no_bending_joints():
    scene = load_scene("paper-circle").with_changes(effects=Effects.from_preset("catenary"))
    counts = build_model(scene).item_counts()
    assert counts["bending_joints"] == 0
    assert counts["slack_elements"] == 2 * 15  # tension-only, in the one cable-force object
    assert counts["cable_force_objects"] == 1
    pushing = load_scene("paper-circle").with_changes(effects=Effects.from_preset("catenary", slack=False))
    counts = build_model(pushing).item_counts()
    assert counts["cable_force_objects"] == 1  # no bending, no slack: the object carries masses, weights, contact
    assert counts["axial_spring_dampers"] == 2 * 15


def test_slack_elements_replace_the_spring_dampers_in_the_one_cable_force_object():
    scene = load_scene("paper-circle").with_changes(effects=Effects.from_preset("full", slack=True))
    counts = build_model(scene).item_counts()
    assert counts["axial_spring_dampers"] == 0
    assert counts["slack_elements"] == 2 * 15
    assert counts["cable_force_objects"] == 1
    assert counts["bending_joints"] == 2 * 14


def test_point_exit_adds_no_pulley_contact(v_shaped):
    counts = build_model(v_shaped()).item_counts()
    assert counts["pulley_contacts"] == 0


# ============================================================================ statics


def test_hanging_cable_tension_steps_by_the_weight_of_each_node(hanging_cable):
    scene = hanging_cable()
    _, [(tension, _)] = settled_tensions(scene)
    weights = scene.gravity * scene.cables[0].node_masses()
    # Element i holds every node below it: T_i - T_{i+1} = weight of node i + 1.
    # 1e-6 N against node weights of 0.4 to 0.9 N: at rest (velocities < 1e-14 m/s),
    # so only Newton's residual is left, which is far smaller.
    np.testing.assert_allclose(-np.diff(tension), weights[1:-1], rtol=0, atol=1e-6)
    assert tension[0] - tension[-1] == pytest.approx(weights[1:-1].sum(), abs=1e-6)


def test_hanging_cable_top_tension_carries_everything_below(hanging_cable):
    scene = hanging_cable(platform_mass=1.0)
    _, [(tension, positions)] = settled_tensions(scene)
    weights = scene.gravity * scene.cables[0].node_masses()
    platform_weight = scene.gravity * scene.platform.mass
    # 1e-6 N out of ~13 N: at rest, see above.
    assert tension[0] == pytest.approx(weights[1:].sum() + platform_weight, abs=1e-6)
    assert tension[-1] == pytest.approx(weights[-1] + platform_weight, abs=1e-6)
    # straight down: no node leaves the vertical through the suspension point
    assert np.abs(positions[:, 0]).max() < 1e-12


def test_creeping_hanging_cable_result_tensions_balance_its_weight(hanging_cable):
    """End to end through ``simulate`` with the paper's solver settings, 3 s.

    The Kelvin-Voigt cable creeps to its static stretch with time constant
    c_i / k_i = 1 s, so it is still moving at 3 s (~1e-5 m/s); the Result's tensions
    include the damping force c_i dl/dt, so the balance of weights holds all the same,
    up to the inertia of the creep.
    """
    solver = SolverSpec(end_time=3.0, step_size=2e-3, spectral_radius=0.5, output_period=0.1)
    scene = hanging_cable(platform_mass=1.0, solver=solver)
    result = simulate(scene)
    tension = result.tensions[0][-1]
    assert np.abs(result.node_velocities[0][-1]).max() > 1e-7  # really still creeping
    weights = scene.gravity * scene.cables[0].node_masses()
    # 1e-4 N: the creep decelerates at ~v / (1 s) ~ 1e-5 m/s^2, an inertia force of
    # ~1e-5 N on the 1.4 kg below the top element (measured residual 9e-6 N).
    assert tension[0] == pytest.approx(weights[1:].sum() + scene.gravity * scene.platform.mass, abs=1e-4)
    np.testing.assert_allclose(-np.diff(tension), weights[1:-1], rtol=0, atol=1e-4)


def test_winch_and_joint_reactions_hold_a_hanging_cable(hanging_cable):
    scene = hanging_cable(platform_mass=1.0)
    model = settle(scene)
    top, bottom = end_forces_on_cable(model, 0)
    cable_weight = scene.gravity * scene.cables[0].mass
    platform_weight = scene.gravity * scene.platform.mass
    # 1e-6 N: at rest; the reactions are Lagrange multipliers solved with the state.
    np.testing.assert_allclose(top, [0.0, cable_weight + platform_weight], rtol=0, atol=1e-6)
    np.testing.assert_allclose(bottom, [0.0, -platform_weight], rtol=0, atol=1e-6)


@pytest.mark.parametrize("preset, slack", [("catenary", False), ("full", False), ("full", True)],
                         ids=["catenary", "full", "full_tension_only"])
def test_v_shaped_cable_end_forces_balance_its_weight(v_shaped, preset, slack):
    scene = v_shaped(Effects.from_preset(preset, slack=slack))
    model = settle(scene)
    for i, cable in enumerate(scene.cables):
        top, bottom = end_forces_on_cable(model, i)
        # The cable is inclined and sags: both end forces have x components (~9 N here),
        # which must cancel; the vertical ones must carry its weight (8.5 N).
        assert abs(top[0]) > 1.0
        # 1e-6 N: at rest (measured residual ~1e-10 N); the internal forces (axial,
        # bending) cancel in the sum over the cable.
        np.testing.assert_allclose(top + bottom, [0.0, scene.gravity * cable.mass], rtol=0, atol=1e-6)


def test_v_shaped_cables_hold_the_platform_weight(v_shaped):
    scene = v_shaped()
    model = settle(scene)
    on_platform = -sum(end_forces_on_cable(model, i)[1] for i in range(scene.n_cables))
    # 1e-6 N: at rest, as above. The point mass sits on the symmetry line.
    np.testing.assert_allclose(on_platform, [0.0, scene.gravity * scene.platform.mass], rtol=0, atol=1e-6)


def test_v_shaped_cable_interior_nodes_balance_with_element_tensions(v_shaped):
    # Bending off, so that the element tensions are the only internal forces.
    scene = v_shaped(Effects.from_preset("catenary"))
    _, cables = settled_tensions(scene)
    for cable, (tension, nodes) in zip(scene.cables, cables):
        up = (nodes[0] - nodes[1]) / np.linalg.norm(nodes[0] - nodes[1])
        down = (nodes[-1] - nodes[-2]) / np.linalg.norm(nodes[-1] - nodes[-2])
        pull = tension[0] * up + tension[-1] * down
        interior_weight = scene.gravity * cable.node_masses()[1:-1].sum()
        # 1e-6 N against 10 to 16 N tensions: at rest.
        np.testing.assert_allclose(pull, [0.0, interior_weight], rtol=0, atol=1e-6)
        assert nodes[len(nodes) // 2, 1] < -0.9  # it really sags below the chord


@pytest.mark.parametrize("slack", [False, True], ids=["spring", "tension_only"])
def test_straight_cable_element_is_a_linear_spring(hanging_cable, slack):
    """Hooke's law: each element of a straight hanging cable stretches by its load over k_i.

    A tension-only element in tension is the same linear spring.
    """
    for platform_mass in (1.0, 4.0):
        scene = hanging_cable(n_elements=2, platform_mass=platform_mass,
                              effects=Effects.from_preset("full", slack=slack))
        cable = scene.cables[0]
        model = settle(scene)
        nodes, _ = cable_state(model, 0)
        stretch = np.linalg.norm(np.diff(nodes, axis=0), axis=1) - cable.element_length
        weights = scene.gravity * cable.node_masses()
        load = np.array([weights[1:].sum(), weights[2:].sum()]) + scene.gravity * platform_mass
        # 1e-6 relative: stretches of 6e-5 to 2.6e-4 m, resolved at rest to ~1e-15 m in
        # coordinates of order 1 m (measured relative error ~1e-12).
        np.testing.assert_allclose(stretch, load / cable.axial_stiffness, rtol=1e-6)
        # and the platform hangs where the two stretched elements put it
        platform = model.coordinate_indices()["platform"]
        data = model.mbs.systemData
        drop = -(data.GetODE2Coordinates(exu.ConfigurationType.Reference)[platform[1]]
                 + data.GetODE2Coordinates()[platform[1]])
        assert drop == pytest.approx(cable.unstrained_length + stretch.sum(), rel=1e-12)


def test_stretch_of_a_straight_cable_is_linear_in_the_load(hanging_cable):
    stretches = []
    for platform_mass in (1.0, 2.0, 4.0):
        scene = hanging_cable(n_elements=2, platform_mass=platform_mass)
        nodes, _ = cable_state(settle(scene), 0)
        stretches.append(-nodes[-1, 1] - scene.cables[0].unstrained_length)
    k_series = scene.cables[0].axial_stiffness / 2
    # Equal steps in load give equal steps in stretch, of (delta M g) / (k_i / 2).
    # 1e-6 relative on steps of 1.2e-4 m and 2.5e-4 m: see the test above.
    assert stretches[1] - stretches[0] == pytest.approx(scene.gravity * 1.0 / k_series, rel=1e-6)
    assert stretches[2] - stretches[1] == pytest.approx(scene.gravity * 2.0 / k_series, rel=1e-6)


# ============================================================================ bad input
# Refused with SceneError naming the field, when the scene is made (no model, no run).


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: PlatformSpec(mass=-2.5), "platform.mass"),
        (lambda: PlatformSpec(mass=0.0), "platform.mass"),
        (lambda: PlatformSpec(inertia=0.0), "platform.inertia"),
        (lambda: CableSpec(linear_density=-0.35), "cable.linear_density"),
        (lambda: CableSpec(unstrained_length=0.0), "cable.unstrained_length"),
        (lambda: CableSpec(unstrained_length=-3.75), "cable.unstrained_length"),
        (lambda: CableSpec(radius=0.0), "cable.radius"),
        (lambda: CableSpec(radius=-0.005), "cable.radius"),
        (lambda: CableSpec(youngs_modulus=0.0), "cable.youngs_modulus"),
        (lambda: CableSpec(youngs_modulus=-1e9), "cable.youngs_modulus"),
        (lambda: CableSpec(damping_constant=-1.0), "cable.damping_constant"),
        (lambda: CableSpec(n_elements=1), "cable.n_elements"),
        (lambda: CableSpec(n_elements=0), "cable.n_elements"),
        (lambda: CableSpec(n_elements=2.5), "cable.n_elements"),
        (lambda: Pulley(radius=0.0), "pulley.radius"),
        (lambda: Pulley(radius=-0.25), "pulley.radius"),
        (lambda: Pulley(contact_stiffness=0.0), "pulley.contact_stiffness"),
        (lambda: Pulley(contact_stiffness=-1e7), "pulley.contact_stiffness"),
        (lambda: Pulley(side=0), "pulley.side"),
        (lambda: Scene(platform=PlatformSpec(anchors=((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)), inertia=(1.0, 1.0, 1.0))),
         "platform.anchors"),
        (lambda: PlatformSpec(anchors=(0.15, 0.1)), "platform.anchors"),
        (lambda: PlatformSpec(anchors=()), "platform.anchors"),
        (lambda: Scene(platform=PlatformSpec(anchors=((0.0, 0.0),))), "platform.anchors"),
        (lambda: CableSpec(youngs_modulus=math.nan), "cable.youngs_modulus"),
        (lambda: CableSpec(linear_density=math.inf), "cable.linear_density"),
        (lambda: PlatformSpec(mass=math.nan), "platform.mass"),
        (lambda: PlatformSpec(initial_pose=(0.0, math.nan, 0.0)), "platform.initial_pose"),
        (lambda: PlatformSpec(anchors=((0.0, math.nan), (0.1, 0.1))), "platform.anchors"),
        (lambda: Pulley(center=(math.nan, 0.0)), "pulley.center"),
        (lambda: Scene(gravity=math.nan), "gravity"),
        (lambda: SolverSpec(step_size=0.0), "solver.step_size"),
        (lambda: SolverSpec(step_size=math.nan), "solver.step_size"),
    ],
)
def test_bad_scene_field_is_refused_naming_the_field(make, field):
    with pytest.raises(SceneError, match=field.replace(".", r"\.").replace("[", r"\[")):
        make()


def test_cable_too_short_for_the_initial_pose_is_refused():
    with pytest.raises(SceneError, match=r"cables\[0\]\.unstrained_length"):
        Scene(cables=(CableSpec(unstrained_length=1.0), CableSpec()))


class _CountingController:
    """Ideal-IK-like controller that only counts how often it is asked (it never should be)."""

    name = "counting"
    uses_pose = False
    uses_tension = False

    def __init__(self):
        self.resets = 0
        self.commands = 0

    def reset(self, scene):
        self.resets += 1

    def command(self, measurement):  # pragma: no cover - must not be reached
        self.commands += 1
        raise AssertionError("the simulation started")


def test_reference_the_cables_cannot_reach_is_refused_before_any_step():
    scene = load_scene("paper-circle")
    far_circle = CircleTrajectory(center=(0.0, -6.0), radius=0.4)  # anchors 6 m below: cables are 3.75 m
    scene = scene.with_changes(trajectory=far_circle, solver=dataclasses.replace(scene.solver, end_time=1.0))
    controller = _CountingController()
    with pytest.raises(UnreachableError, match=r"cable 1"):
        simulate(scene, controller)
    assert controller.commands == 0
    with pytest.raises(UnreachableError):
        build_model(scene)


def test_reference_through_a_pulley_is_refused():
    scene = load_scene("paper-circle")
    # a circle of radius 1.75 about the origin passes over both pulley centres
    through = CircleTrajectory(center=(0.0, 0.0), radius=1.75, angular_rate=1.0)
    scene = scene.with_changes(trajectory=through, solver=dataclasses.replace(scene.solver, end_time=7.0))
    with pytest.raises(UnreachableError):
        build_model(scene)
