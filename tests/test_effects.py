"""Tests of the effects a scene calls for (cdpr_exu.scenes.scene.Effects and the builder).

Sections: switching an effect off removes its items (counted with
``Model.item_counts``); every preset runs the paper scene; physics limits of the
model ladder: a very stiff elastic cable matches the ideal (inextensible) one and
ideal inverse kinematics, and a massless cable is straight.
"""

from __future__ import annotations

import math
from dataclasses import replace

import exudyn as exu
import numpy as np
import pytest

from cdpr_exu.builder.model import build_model
from cdpr_exu.scenes.scene import PRESETS, Effects, load_scene
from cdpr_exu.run.simulate import simulate, solver_settings

from conftest import settling_solver

#: Items of the paper scene (2 cables x 15 elements) with every effect on.
NODES, ELEMENTS, JOINTS = 2 * 16, 2 * 15, 2 * 14


@pytest.fixture(scope="module")
def paper_scene():
    return load_scene("paper-circle")


def counts(scene, preset="full", **overrides):
    """Item counts of ``scene`` built with a preset and single-effect overrides."""
    return build_model(scene.with_changes(effects=Effects.from_preset(preset, **overrides))).item_counts()


# ============================================================================ items


def test_paper_preset_adds_every_item_of_the_paper_model(paper_scene):
    paper = counts(paper_scene, "paper")
    assert paper["mass_points"] == NODES
    assert paper["axial_spring_dampers"] == ELEMENTS  # Exudyn's spring-dampers, which push as well
    assert paper["bending_joints"] == JOINTS
    assert paper["pulley_contacts"] > 0
    assert paper["gravity_loads"] == NODES + 1  # every node and the platform
    assert paper["slack_elements"] == 0 and paper["massless_ropes"] == 0


def test_full_preset_is_the_paper_model_with_tension_only_elements(paper_scene):
    full, paper = counts(paper_scene), counts(paper_scene, "paper")
    assert full["axial_spring_dampers"] == 0 and full["slack_elements"] == ELEMENTS
    assert full["cable_force_objects"] == 1  # the tension-only elements ride in the bending object
    for item in ("mass_points", "bending_joints", "pulley_contacts", "gravity_loads", "massless_ropes"):
        assert full[item] == paper[item], item


def test_bending_off_removes_the_bending_joints_and_their_python_forces(paper_scene):
    off = counts(paper_scene, "paper", bending=False, bending_damping=False)
    assert off["bending_joints"] == 0
    assert off["cable_force_objects"] == 1  # it carries the masses and weights, with no Python function
    assert off["axial_spring_dampers"] == ELEMENTS and off["mass_points"] == NODES
    tension_only = counts(paper_scene, bending=False, bending_damping=False)
    assert tension_only["bending_joints"] == 0 and tension_only["cable_force_objects"] == 1  # the slack elements


def test_contact_off_removes_the_pulley_contacts(paper_scene):
    off = counts(paper_scene, pulley_contact=False)
    assert off["pulley_contacts"] == 0
    assert off["bending_joints"] == JOINTS


def test_slack_replaces_the_spring_dampers_by_slack_elements(paper_scene):
    slack = counts(paper_scene, slack=True)
    assert slack["axial_spring_dampers"] == 0
    assert slack["slack_elements"] == ELEMENTS
    assert slack["cable_force_objects"] == 1  # bending and slack share the one object


def test_cable_mass_off_gives_massless_ropes_and_no_mass_points(paper_scene):
    massless = counts(paper_scene, cable_mass=False, bending=False, bending_damping=False, pulley_contact=False)
    assert massless["mass_points"] == 0
    assert massless["massless_ropes"] == 2
    assert massless["axial_spring_dampers"] == massless["bending_joints"] == massless["pulley_contacts"] == 0


def test_gravity_off_adds_no_loads(paper_scene):
    assert counts(paper_scene, gravity=False)["gravity_loads"] == 0
    assert counts(paper_scene, "ideal", gravity=False)["gravity_loads"] == 0


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_each_preset_adds_only_the_items_of_its_effects(paper_scene, preset):
    flags = PRESETS[preset]
    got = counts(paper_scene, preset)
    assert (got["mass_points"] > 0) == flags["cable_mass"]
    assert (got["massless_ropes"] > 0) == (not flags["cable_mass"])
    assert (got["bending_joints"] > 0) == flags["bending"]
    assert (got["pulley_contacts"] > 0) == flags["pulley_contact"]
    assert (got["gravity_loads"] > 0) == flags["gravity"]


def test_linear_bending_has_the_same_joints_in_constant_matrices_without_a_force_function(paper_scene):
    """Without pulley contact (whose forces live in the same object, computed in Python)."""
    effects = Effects.from_preset("paper", bending_model="linear", pulley_contact=False)
    model = build_model(paper_scene.with_changes(effects=effects))
    assert model.item_counts()["bending_joints"] == JOINTS
    item = model.mbs.GetObject(model.cable_forces.object)
    assert item["forceUserFunction"] == 0  # no Python call per Newton iteration
    assert len(item["forceVector"]) == 2 * NODES  # -K q_ref: K acts on absolute positions


def test_linear_bending_of_a_straight_cable_is_zero():
    """The curvature-vector spring of a straight, evenly stretched cable exerts no force.

    The reference configuration over a pulley is bent; K (q_ref + q) must vanish for
    any straight configuration, so the force vector -K q_ref has to cancel K q_ref.
    """
    from cdpr_exu.physics.bending import cable_joints, curvature_stiffness_matrix

    joints = cable_joints([6])
    k_matrix = curvature_stiffness_matrix(6, joints, 2.0, 0.1)
    straight = np.column_stack([np.linspace(0.3, 0.9, 6), np.linspace(-0.2, -1.0, 6)]).ravel()
    bent = np.column_stack([0.1 * np.cos(np.linspace(0, 2, 6)), 0.1 * np.sin(np.linspace(0, 2, 6))]).ravel()
    displacement = straight - bent  # what Exudyn passes when the reference is the bent shape
    force = -(k_matrix @ displacement) - k_matrix @ bent
    assert np.abs(force).max() < 1e-12 * np.abs(k_matrix).max()


# ============================================================================ runs


@pytest.mark.slow
@pytest.mark.parametrize("preset,model", [("ideal", "exact"), ("elastic", "exact"), ("catenary", "exact"),
                                          ("full", "exact"), ("full", "linear")])
def test_each_preset_runs_the_paper_scene_for_half_a_second(paper_scene, preset, model):
    # 0.5 s: the catenary preset (no bending) is thrown above the pulleys at about 0.8 s.
    scene = paper_scene.with_changes(effects=Effects.from_preset(preset, bending_model=model),
                                     solver=replace(paper_scene.solver, end_time=0.5))
    result = simulate(scene)
    assert result.status == "completed"
    assert np.all(np.isfinite(result.pose))
    # in half a second the platform has started along the circle, not left it by metres
    assert np.abs(result.error[:, :2]).max() < 0.2


# ============================================================================ limits


def _with_stiffness(scene, factor):
    return scene.with_changes(cables=tuple(replace(c, youngs_modulus=c.youngs_modulus * factor,
                                                   damping_constant=c.damping_constant * factor)
                                           for c in scene.cables))


@pytest.mark.slow
def test_very_stiff_elastic_cables_follow_the_ideal_cables_on_the_paper_circle(paper_scene):
    solver = replace(paper_scene.solver, end_time=1.0)
    ideal = simulate(paper_scene.with_changes(effects=Effects.from_preset("ideal"), solver=solver))
    paths = {}
    for factor in (1.0, 100.0):
        scene = _with_stiffness(paper_scene, factor).with_changes(effects=Effects.from_preset("elastic"),
                                                                  solver=solver)
        paths[factor] = np.linalg.norm(simulate(scene).pose[:, :2] - ideal.pose[:, :2], axis=1)
    # Measured over 3 s: 1.5 mm at the paper's E, 0.05 mm at 100 E (the ideal rope is
    # 1000 EA, not rigid). The stiffer the cable, the closer to the ideal one.
    assert paths[100.0].max() < 0.2e-3
    assert paths[100.0].max() < 0.2 * paths[1.0].max()


def test_very_stiff_massless_cables_hold_the_platform_at_its_ideal_inverse_kinematics_pose():
    """A point mass on two massless cables from the pulley centres (paper-catenary-fixed).

    Ideal inverse kinematics puts it at the held pose (0, -1.75) with straight cables
    at 45 degrees: tension m g / (2 sin 45). A massless rope of axial rigidity EA
    (its unstrained length L plus the fixed segment the builder keeps below the
    pulley) stretches by T L / EA, so the mass sits lower by that over sin 45
    (0.34 mm at the paper's E); 100 times stiffer, 100 times less; the ideal rope is
    1000 EA.
    """
    from cdpr_exu.builder.model import MIN_WINCH_SEGMENT

    scene = load_scene("paper-catenary-fixed")
    # 8 s: the Kelvin-Voigt creep of the stretch (time constant dn / E = 1 s) has
    # decayed to 3e-4 of its start.
    scene = scene.with_changes(solver=replace(scene.solver, end_time=8.0))
    cable = scene.cables[0]
    tension = scene.platform.mass * scene.gravity / (2.0 * math.sin(math.pi / 4))
    for preset, factor in (("ideal", 1.0), ("elastic", 1.0), ("elastic", 100.0)):
        result = simulate(_with_stiffness(scene, factor).with_changes(effects=Effects.from_preset(preset)))
        rigidity = cable.axial_rigidity * factor * (1000.0 if preset == "ideal" else 1.0)
        drop = tension * (cable.unstrained_length + MIN_WINCH_SEGMENT) / rigidity / math.sin(math.pi / 4)
        x, z, _ = result.pose[-1]
        assert x == pytest.approx(0.0, abs=1e-9)
        # 1 %: the cables turn slightly as they stretch, and the creep's last 3e-4
        assert -1.75 - z == pytest.approx(drop, rel=0.01)
        assert result.tensions[0][-1, 0] == pytest.approx(tension, rel=1e-4)


@pytest.mark.parametrize("linear_density", [1e-2, 1e-3, 1e-4])
def test_a_massless_cable_is_straight(linear_density):
    """A lumped cable's sag vanishes with its mass: the limit is the straight rope.

    The V of paper-catenary-fixed without bending, settled to rest. A light cable of
    weight w per length under tension T sags by the shallow-sag parabola
    w cos(alpha) L^2 / (8 T) at mid-span (alpha = 45 degrees, T = m g / (2 sin 45)
    from the platform alone), which is 0.77 mm at w = 1e-3 kg/m x g: in proportion to
    the mass, so zero for a massless cable. The 3 % allow for the cable's own weight
    in T and for the 10 lumped elements (measured: 0.03 % at 1e-4 kg/m, 2.4 % at 1e-2).
    """
    base = load_scene("paper-catenary-fixed")
    cables = tuple(replace(c, linear_density=linear_density, n_elements=10) for c in base.cables)
    scene = base.with_changes(cables=cables, effects=Effects.from_preset("catenary"), solver=settling_solver())
    model = build_model(scene)
    settings = solver_settings(scene)
    settings.timeIntegration.generalizedAlpha.computeInitialAccelerations = False  # see test_model.settle
    model.mbs.SolveDynamic(settings)
    data = model.mbs.systemData
    index = model.coordinate_indices()["cable_0"]
    nodes = data.GetODE2Coordinates(exu.ConfigurationType.Reference)[index] + data.GetODE2Coordinates()[index]
    chord = nodes[-1] - nodes[0]
    normal = np.array([-chord[1], chord[0]]) / np.linalg.norm(chord)
    sag = np.abs((nodes - nodes[0]) @ normal).max()
    tension = scene.platform.mass * scene.gravity / (2.0 * math.sin(math.pi / 4))
    parabola = linear_density * scene.gravity * math.cos(math.pi / 4) * np.linalg.norm(chord) ** 2 / (8 * tension)
    assert sag == pytest.approx(parabola, rel=0.03)
