"""Elastic-catenary statics of spatial robots (cdpr_exu.physics.spatial_statics): pure maths, no Exudyn."""

import math

import numpy as np
import pytest

import cdpr_exu.physics.spatial_statics as spatial_statics
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import left_jacobian, rotation_from_vector
from cdpr_exu.physics.spatial_statics import SpatialCable, SpatialPlatform, solve_cable, solve_spatial_statics
from cdpr_exu.statics.statics import SuspendedCable, SuspendedPlatform, solve_forward_statics
from conftest import ASYMMETRIC_LENGTHS, PAPER_CATENARY_CABLE, four_cable_robot

# The paper's cable, w = 3.43 N/m and EA = 7.85e4 N, and the four-cable robot of tests/conftest.py
# (3 m x 3 m frame, exits at z = 0; 0.2 m square platform, anchors 5 cm above its centre of mass).
W, EA = PAPER_CATENARY_CABLE.weight_per_length, PAPER_CATENARY_CABLE.axial_stiffness
PLATFORM_HALF = 0.1


def net_wrench(platform, equilibrium):
    """Cable forces plus weight, and their moment about the centre of mass, recomputed from the result."""
    force = equilibrium.forces_on_platform.sum(axis=0) + [0.0, 0.0, -platform.mass * platform.gravity]
    arms = equilibrium.anchor_points - equilibrium.position
    moment = np.cross(arms, equilibrium.forces_on_platform).sum(axis=0)
    return force, moment


BOTH = [pytest.param(False, id="point-mass"), pytest.param(True, id="rigid")]


# ---------------------------------------------------------------------------
# 1. a robot in one vertical plane is the planar robot
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("rigid", BOTH)
@pytest.mark.parametrize("azimuth", [0.0, math.radians(35.0)])
def test_robot_in_one_vertical_plane_reproduces_the_planar_statics(rigid, azimuth):
    """Two cables and the platform in a vertical plane at any azimuth: the planar answer of cdpr_exu.statics.statics."""
    along = np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    planar_anchors = [(-0.15, 0.1), (0.15, 0.1)] if rigid else [(0.0, 0.0), (0.0, 0.0)]
    planar = SuspendedPlatform([SuspendedCable(W, EA, anchor=anchor, exit_point=(sign * 1.75, 0.0))
                                for sign, anchor in zip((-1, 1), planar_anchors)], mass=2.5)
    spatial = SpatialPlatform([SpatialCable(sign * 1.75 * along, W, EA, anchor=anchor[0] * along + [0, 0, anchor[1]])
                               for sign, anchor in zip((-1, 1), planar_anchors)], mass=2.5, inertia=(0.1,) * 3)
    lengths = [2.45, 2.5]
    expected = solve_forward_statics(planar, lengths)
    found = solve_spatial_statics(spatial, lengths)
    # Both solvers stop at a scaled residual of 1e-12 (or the 1e3 x noise floor of the
    # stiff cables, 2e-6 N on 30 N): the poses agree to 1e-9 m, the tensions to 1e-7 N
    # (measured: 1.2e-13 m, 1e-16 rad, 2e-10 N).
    np.testing.assert_allclose(found.position @ along, expected.position[0], atol=1e-9)
    np.testing.assert_allclose(found.position[2], expected.position[1], atol=1e-9)
    normal = np.cross(along, [0.0, 0.0, 1.0])
    assert abs(found.position @ normal) < 1e-12
    # the planar rotation phi turns ``along`` towards +z: about the axis along x e_z
    np.testing.assert_allclose(found.rotation_vector, expected.rotation * np.cross(along, [0.0, 0.0, 1.0]), atol=1e-9)
    np.testing.assert_allclose(found.tensions_at_anchor, expected.tensions_at_anchor, atol=1e-7)
    np.testing.assert_allclose(found.tensions_at_exit, [c.tension_at_exit for c in expected.cables], atol=1e-7)


# ---------------------------------------------------------------------------
# 2. symmetry
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("rigid", BOTH)
def test_symmetric_four_cable_robot_hangs_on_the_axis_with_equal_tensions_and_no_rotation(rigid):
    platform = four_cable_robot(rigid)
    equilibrium = solve_spatial_statics(platform, [2.5] * 4)
    # the solve is a Newton iteration to a scaled residual of 1e-12: symmetry holds to round-off
    np.testing.assert_allclose(equilibrium.position[:2], 0.0, atol=1e-12)
    np.testing.assert_allclose(equilibrium.rotation_vector, 0.0, atol=1e-12)
    tensions = equilibrium.tensions_at_anchor
    np.testing.assert_allclose(tensions, tensions.mean(), rtol=1e-12)
    # each cable carries a quarter of the weight at its anchor
    np.testing.assert_allclose(equilibrium.forces_on_platform[:, 2], platform.mass * platform.gravity / 4, rtol=1e-10)
    assert equilibrium.is_stable


# ---------------------------------------------------------------------------
# 3. force and moment balance
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("rigid", BOTH)
def test_cable_forces_balance_the_weight_and_their_moments_cancel(rigid):
    platform = four_cable_robot(rigid)
    equilibrium = solve_spatial_statics(platform, ASYMMETRIC_LENGTHS)
    force, moment = net_wrench(platform, equilibrium)
    weight = platform.mass * platform.gravity
    # the solver's noise floor: 1e-9 (1 + EA / weights) relative, 2e-6 of the 80 N of weights here
    assert np.abs(force).max() < 1e-7 * weight
    assert np.abs(moment).max() < 1e-7 * weight * PLATFORM_HALF
    assert np.linalg.norm(equilibrium.rotation_vector) > 1e-2 if rigid else True  # it does turn
    # each cable's two end forces carry its own weight
    for cable in equilibrium.cables:
        total = cable.force_on_platform + cable.force_on_exit
        np.testing.assert_allclose(total, [0.0, 0.0, -W * cable.unstrained_length], atol=1e-9)
    assert equilibrium.is_stable


@pytest.mark.parametrize("rigid", BOTH)
def test_stiffness_is_minus_the_derivative_of_the_generalised_force(rigid):
    platform = four_cable_robot(rigid)
    equilibrium = solve_spatial_statics(platform, ASYMMETRIC_LENGTHS)
    dof = platform.degrees_of_freedom
    x0 = np.concatenate([equilibrium.position, equilibrium.rotation_vector])[:dof]

    def generalised_force(x):
        theta = x[3:] if dof == 6 else np.zeros(3)
        rotation = rotation_from_vector(theta)
        force, moment = np.array([0.0, 0.0, -platform.mass * platform.gravity]), np.zeros(3)
        for cable, length in zip(platform.cables, ASYMMETRIC_LENGTHS):
            arm = rotation @ np.array(cable.anchor)
            cable_equilibrium, _ = solve_cable(cable, length, x[:3] + arm)
            force += cable_equilibrium.force_on_platform
            moment += np.cross(arm, cable_equilibrium.force_on_platform)
        return np.concatenate([force, left_jacobian(theta).T @ moment])[:dof]

    h = 1e-6
    numeric = -np.array([(generalised_force(x0 + h * e) - generalised_force(x0 - h * e)) / (2 * h)
                         for e in np.eye(dof)]).T
    # central differences of catenary forces solved to 1e-12 of the length: 1e-6 of the largest entry
    np.testing.assert_allclose(equilibrium.stiffness, numeric, atol=1e-6 * np.abs(numeric).max())


def test_four_cables_on_a_point_mass_share_the_load_by_their_elasticity():
    """Statically indeterminate: a stiffer cable takes more load, at the same lengths."""
    soft = four_cable_robot(False)
    cables = list(soft.cables)
    cables[0] = SpatialCable(cables[0].exit_point, W, 4 * EA)
    stiff = SpatialPlatform(cables, mass=soft.mass)
    lengths = [2.5] * 4
    base = solve_spatial_statics(soft, lengths).tensions_at_anchor
    equilibrium = solve_spatial_statics(stiff, lengths)
    changed = equilibrium.tensions_at_anchor
    # measured: the stiff cable's diagonal (0, 2) takes 1.7 % more, the other diagonal 1.6 % less
    assert changed[0] > base[0] * 1.01 and changed[2] > base[2] * 1.01
    assert changed[1] < base[1] * 0.99 and changed[3] < base[3] * 0.99
    assert equilibrium.position[0] > 0.0 and equilibrium.position[1] > 0.0  # towards the stiff cable's exit
    force, _ = net_wrench(stiff, equilibrium)
    assert np.abs(force).max() < 1e-7 * stiff.mass * stiff.gravity  # the noise floor, as above


def test_a_cable_profile_starts_at_the_anchor_and_ends_at_the_exit():
    equilibrium = solve_spatial_statics(four_cable_robot(True), ASYMMETRIC_LENGTHS)
    for cable in equilibrium.cables:
        points = cable.points([0.0, cable.unstrained_length])
        # the closed-form profile of a span solved to 1e-12 of the length
        np.testing.assert_allclose(points[0], cable.anchor_point, atol=1e-12)
        np.testing.assert_allclose(points[1], cable.exit_point, atol=1e-10)


# ---------------------------------------------------------------------------
# 6. bad input, refused before any solve
# ---------------------------------------------------------------------------
@pytest.fixture
def no_solve(monkeypatch):
    """Fail the test if a catenary or the starting pose is ever solved."""

    def forbidden(*args, **kwargs):
        raise AssertionError("a solve started before the input was refused")

    monkeypatch.setattr(spatial_statics, "solve_cable", forbidden)
    monkeypatch.setattr(spatial_statics, "minimize", forbidden)


def _cable(**changes):
    fields = dict(exit_point=(1.5, 1.5, 0.0), weight_per_length=W, axial_stiffness=EA)
    fields.update(changes)
    return SpatialCable(**fields)


@pytest.mark.parametrize("changes, field", [
    (dict(exit_point=(1.0, float("nan"), 0.0)), "exit_point"),
    (dict(exit_point=(1.0, 0.0)), "exit_point"),
    (dict(anchor=(0.0, float("inf"), 0.0)), "anchor"),
    (dict(weight_per_length=-1.0), "weight_per_length"),
    (dict(axial_stiffness=0.0), "axial_stiffness"),
    (dict(axial_stiffness=float("nan")), "axial_stiffness"),
])
def test_a_bad_cable_is_refused_naming_the_field(changes, field):
    with pytest.raises(SceneError, match=field):
        _cable(**changes)


def test_a_bad_platform_is_refused_naming_the_field():
    good = list(four_cable_robot(True).cables)
    with pytest.raises(SceneError, match="mass"):
        SpatialPlatform(good, mass=-1.0)
    with pytest.raises(SceneError, match="mass"):
        SpatialPlatform(good, mass=float("nan"))
    with pytest.raises(SceneError, match="inertia"):
        SpatialPlatform(good, mass=1.0, inertia=(0.1, -0.1, 0.1))
    with pytest.raises(SceneError, match="exit_point"):
        SpatialPlatform([good[0], _cable(exit_point=good[0].exit_point, anchor=(0.0, 0.1, 0.0))], mass=1.0)
    with pytest.raises(SceneError, match="anchor"):
        SpatialPlatform([good[0], _cable(exit_point=(9.0, 0.0, 0.0), anchor=good[0].anchor)], mass=1.0)
    with pytest.raises(SceneError, match="cables"):
        SpatialPlatform([], mass=1.0)
    with pytest.raises(SceneError, match="cables"):
        SpatialPlatform([good[0]], mass=1.0)  # a rigid body on one cable turns freely about it
    with pytest.raises(SceneError, match="cables"):  # anchors on a line through the centre of mass
        SpatialPlatform([_cable(anchor=(0.1, 0.0, 0.0)), _cable(exit_point=(-1.5, 0, 0), anchor=(-0.1, 0.0, 0.0))],
                        mass=1.0)
    with pytest.raises(SceneError, match="cables"):
        SpatialPlatform(["not a cable"], mass=1.0)


@pytest.mark.parametrize("lengths, field", [
    ([2.5, 2.5, 2.5], "unstrained_lengths"),
    ([2.5, 2.5, 2.5, -1.0], "unstrained_lengths"),
    ([2.5, 2.5, 2.5, float("nan")], "unstrained_lengths"),
])
def test_bad_lengths_are_refused_before_any_solve(no_solve, lengths, field):
    with pytest.raises(SceneError, match=field):
        solve_spatial_statics(four_cable_robot(False), lengths)


def test_cables_that_cannot_both_reach_the_platform_are_refused_before_any_solve(no_solve):
    # opposite exits are 4.24 m apart; two 1.9 m cables reach 4.18 m at 10 % strain
    with pytest.raises(UnreachableError, match=r"unstrained_lengths: cables\[0\] and cables\[2\] cannot both reach"):
        solve_spatial_statics(four_cable_robot(False), [1.9, 2.5, 1.9, 2.5])


def test_bad_options_are_refused_before_any_solve(no_solve):
    platform = four_cable_robot(True)
    with pytest.raises(SceneError, match="initial_pose"):
        solve_spatial_statics(platform, [2.5] * 4, initial_pose=[0.0, 0.0, -1.0])
    with pytest.raises(SceneError, match="external_wrench"):
        solve_spatial_statics(platform, [2.5] * 4, external_wrench=[0.0, 0.0, 1.0])
    with pytest.raises(SceneError, match="max_strain"):
        solve_spatial_statics(platform, [2.5] * 4, max_strain=0.0)
    with pytest.raises(SceneError, match="platform"):
        solve_spatial_statics("platform", [2.5] * 4)


def test_no_equilibrium_within_the_tension_limit_is_a_clear_error():
    # short cables: the platform can only hang from them at tensions far above 10 N
    with pytest.raises(UnreachableError, match="no equilibrium found for unstrained_lengths"):
        solve_spatial_statics(four_cable_robot(False), [2.3] * 4, max_tension=10.0)


# ---------------------------------------------------------------------------
# the inverse: lengths that hold a pose
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["spatial-cogiro", "spatial-ipanema"])
def test_the_catenaries_of_the_inverse_lengths_hold_the_platform_at_the_asked_pose(name):
    from cdpr_exu.physics.spatial_statics import solve_inverse_spatial_statics
    from cdpr_exu.scenes.scene import load_scene

    scene = load_scene(name)
    platform = scene.catenary_platform()
    rest = solve_spatial_statics(platform, scene.unstrained_lengths)
    tensions = np.array([c.catenary.horizontal_tension for c in rest.cables])
    pose = np.concatenate([rest.position, rest.rotation_vector])
    # at the rest pose, with the rest's tensions: the scene's own lengths come back
    back = solve_inverse_spatial_statics(platform, pose, tensions)
    np.testing.assert_allclose(back.unstrained_lengths, scene.unstrained_lengths, atol=1e-9)
    # elsewhere: the forward statics of the inverse lengths put the platform there (measured
    # 5e-12 m and rad for both robots: two solvers of the same equations, each to 1e-9 or better)
    target = pose + np.array([0.1, -0.05, 0.02, 0.0, 0.0, 0.02])
    inverse = solve_inverse_spatial_statics(platform, target, back.horizontal_tensions)
    forward = solve_spatial_statics(platform, inverse.unstrained_lengths, initial_pose=target)
    np.testing.assert_allclose(forward.position, target[:3], atol=1e-9)
    np.testing.assert_allclose(forward.rotation_vector, target[3:], atol=1e-9)
    # the tensions stay nearest the start: an over-constrained robot keeps its internal tension
    assert np.abs(inverse.horizontal_tensions - tensions).max() < 0.5 * tensions.max()


def test_the_inverse_refuses_a_pose_only_a_pushing_cable_could_hold():
    from cdpr_exu.physics.spatial_statics import solve_inverse_spatial_statics

    platform = four_cable_robot(rigid=False)
    with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace|did not converge"):
        solve_inverse_spatial_statics(platform, [0.0, 0.0, 0.5], np.full(4, 10.0))  # above the exits
