"""Tests of the kineto-static equilibrium of a platform on catenary cables (cdpr_exu.statics.statics)."""

import math

import numpy as np
import pytest

from cdpr_exu.physics.catenary import CatenaryCable, solve_forward
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.statics.statics import (
    Pulley,
    SuspendedCable,
    SuspendedPlatform,
    inertial_wrench,
    solve_forward_statics,
    solve_inverse_statics,
    straight_cable_pose,
)

# The paper's cable (radius 5 mm, E = 1e9 Pa, 0.35 kg/m) and robot geometry.
CABLE = CatenaryCable.from_material(1.0, 0.005, 1e9, 0.35)
W, EA = CABLE.weight_per_length, CABLE.axial_stiffness
PULLEY_X, PULLEY_RADIUS = 1.75, 0.25
PLATFORM_LENGTH, PLATFORM_HEIGHT = 0.3, 0.2
STRAIGHT_LENGTH = 1.75 * math.sqrt(2)  # scenario 2: (+-1.75, 0) to (0, -1.75)


def make_platform(pulleys=False, rigid=False, mass=None):
    cables = []
    for sign in (-1, 1):
        anchor = (sign * PLATFORM_LENGTH / 2, PLATFORM_HEIGHT / 2) if rigid else (0.0, 0.0)
        if pulleys:
            upper = dict(pulley=Pulley((sign * PULLEY_X, 0.0), PULLEY_RADIUS, side=sign))
        else:
            upper = dict(exit_point=(sign * PULLEY_X, 0.0))
        cables.append(SuspendedCable(W, EA, anchor=anchor, **upper))
    if mass is None:
        mass = 2.5 if rigid else 1.0
    return SuspendedPlatform(cables, mass=mass, moment_of_inertia=0.0271)


def net_wrench(platform, equilibrium):
    """Sum of cable forces, weight and external load; moment about the centre of mass."""
    total = equilibrium.external_wrench.copy()
    total[1] -= platform.mass * platform.gravity
    for cable in equilibrium.cables:
        force = cable.force_on_platform
        arm = cable.anchor_point - equilibrium.position
        total[:2] += force
        total[2] += arm[0] * force[1] - arm[1] * force[0]
    return total


ALL_PLATFORMS = [
    pytest.param(False, False, id="point-mass"),
    pytest.param(False, True, id="rigid"),
    pytest.param(True, False, id="point-mass-pulleys"),
    pytest.param(True, True, id="rigid-pulleys"),
]


# ---------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------
def test_invalid_parameters_raise_scene_error_naming_them():
    with pytest.raises(SceneError, match="exactly one of exit_point and pulley"):
        SuspendedCable(W, EA)
    with pytest.raises(SceneError, match="axial_stiffness"):
        SuspendedCable(W, float("nan"), exit_point=(0, 0))
    with pytest.raises(SceneError, match="radius"):
        Pulley((0, 0), -0.2)
    with pytest.raises(SceneError, match="side"):
        Pulley((0, 0), 0.2, side=0)
    with pytest.raises(SceneError, match="mass"):
        SuspendedPlatform(make_platform().cables, mass=-1.0)
    with pytest.raises(SceneError, match="unstrained_lengths"):
        solve_forward_statics(make_platform(), [2.0, -1.0])
    with pytest.raises(SceneError, match="external_wrench"):
        solve_inverse_statics(make_platform(), (0, -1.5), external_wrench=(1.0, 2.0))


def test_inverse_statics_must_be_square():
    with pytest.raises(SceneError, match="as many unknowns as equations"):
        solve_inverse_statics(make_platform(rigid=True), (0, -1.5), rotation=0.0)
    with pytest.raises(SceneError, match="no rotation"):
        solve_inverse_statics(make_platform(), (0, -1.5), rotation=0.3)


# ---------------------------------------------------------------------------
# point mass
# ---------------------------------------------------------------------------
def test_point_mass_in_the_symmetric_middle_hangs_on_equal_tensions():
    platform = make_platform()
    equilibrium = solve_inverse_statics(platform, (0.0, -1.75))
    tensions = equilibrium.tensions_at_anchor
    # mirror-symmetric problem solved by the same Newton steps: round-off only
    assert tensions[0] == pytest.approx(tensions[1], rel=1e-12)
    forces = equilibrium.forces_on_platform
    # the vertical components carry the weight, the horizontal ones cancel;
    # the Newton tolerance is 1e-12 of the load
    assert forces[:, 1].sum() == pytest.approx(platform.mass * platform.gravity, rel=1e-11)
    assert forces[:, 0].sum() == pytest.approx(0.0, abs=1e-10)
    # the sagging cable meets the platform less steeply than the straight 45 degrees,
    # so its tension exceeds the massless Mg / (2 sin 45) = 6.94 N
    assert tensions[0] > platform.mass * platform.gravity / math.sqrt(2)


@pytest.mark.parametrize("pulleys, rigid", ALL_PLATFORMS)
@pytest.mark.parametrize("position", [(0.0, -1.75), (0.5, -1.5), (-0.9, -2.2), (1.2, -0.8)])
def test_forward_statics_of_the_inverse_returns_the_position(pulleys, rigid, position):
    platform = make_platform(pulleys, rigid)
    inverse = solve_inverse_statics(platform, position)
    forward = solve_forward_statics(platform, inverse.unstrained_lengths)
    # both Newton solves stop at 1e-12 of the load; the pose error is that over the
    # stiffness (>= ~1e2 N/m here), far below 1e-9 m
    np.testing.assert_allclose(forward.position, position, atol=1e-9)
    assert forward.rotation == pytest.approx(inverse.rotation, abs=1e-9)
    assert forward.is_stable


@pytest.mark.parametrize("pulleys, rigid", ALL_PLATFORMS)
def test_inverse_statics_of_the_forward_returns_the_lengths(pulleys, rigid):
    platform = make_platform(pulleys, rigid)
    lengths = [2.3, 2.9] if not pulleys else [2.9, 3.5]
    forward = solve_forward_statics(platform, lengths)
    inverse = solve_inverse_statics(platform, forward.position)
    # lengths inherit the forward pose error (~1e-12 m) times a gain of order 1
    np.testing.assert_allclose(inverse.unstrained_lengths, lengths, rtol=1e-9)


def test_forward_statics_finds_a_pendulum_pulled_aside_by_a_slack_heavy_cable():
    """Near-vertical stiff cable plus a long sagging one: a curved, ill-conditioned valley."""
    platform = make_platform()
    lengths = solve_inverse_statics(platform, (-1.4, -1.85)).unstrained_lengths
    assert lengths[1] > 2 * lengths[0]  # the right cable hangs in a deep sag
    equilibrium = solve_forward_statics(platform, lengths)
    # stiffness ratio ~1e4 between along and across the left cable; the pose is
    # still found to the Newton tolerance over the soft stiffness (~10 N/m)
    np.testing.assert_allclose(equilibrium.position, (-1.4, -1.85), atol=1e-9)


@pytest.mark.parametrize("pulleys, rigid", ALL_PLATFORMS)
def test_equilibrium_balances_forces_and_moments(pulleys, rigid):
    platform = make_platform(pulleys, rigid)
    for equilibrium in (
        solve_inverse_statics(platform, (0.4, -1.6)),
        solve_forward_statics(platform, [2.2, 2.8] if not pulleys else [2.8, 3.4]),
    ):
        residual = net_wrench(platform, equilibrium)
        # Newton tolerance 1e-12 of the ~40 N load (1e-11 in the moment's N m)
        np.testing.assert_allclose(residual, 0.0, atol=1e-9)


def test_platform_weight_and_cable_weight_hang_on_the_exits():
    platform = make_platform()
    equilibrium = solve_forward_statics(platform, [2.4, 2.6])
    upward = sum(-c.catenary.force_on_b[1] for c in equilibrium.cables)
    cables = sum(W * c.unstrained_length for c in equilibrium.cables)
    # the exits carry the platform and both cables: global balance, to round-off
    assert upward == pytest.approx(platform.mass * platform.gravity + cables, rel=1e-10)


# ---------------------------------------------------------------------------
# rigid platform
# ---------------------------------------------------------------------------
def test_rigid_platform_turns_until_the_cable_moments_cancel():
    platform = make_platform(rigid=True)
    equilibrium = solve_inverse_statics(platform, (0.4, -1.6))
    # off-centre, the two cables pull at different angles: the platform must tilt
    assert abs(equilibrium.rotation) > 0.05
    moments = [
        (c.anchor_point - equilibrium.position)[0] * c.force_on_platform[1]
        - (c.anchor_point - equilibrium.position)[1] * c.force_on_platform[0]
        for c in equilibrium.cables
    ]
    # the two cable moments about the centre of mass cancel (Newton tolerance)
    assert moments[0] == pytest.approx(-moments[1], abs=1e-10)
    assert abs(moments[0]) > 0.1  # and they are not trivially zero
    # on the other side the platform tilts the other way, by symmetry
    mirrored = solve_inverse_statics(platform, (-0.4, -1.6))
    assert mirrored.rotation == pytest.approx(-equilibrium.rotation, rel=1e-9)


def test_rigid_platform_near_the_workspace_edge_tilts_by_about_a_radian():
    platform = make_platform(rigid=True)
    # the left anchor would sit right under its exit: the platform turns until the
    # weight, the near-vertical left cable and the right cable meet at a point
    equilibrium = solve_inverse_statics(platform, (-1.6, -1.85))
    assert -1.2 < equilibrium.rotation < -0.8
    assert equilibrium.is_stable
    np.testing.assert_allclose(net_wrench(platform, equilibrium), 0.0, atol=1e-9)  # Newton tolerance


def test_rigid_platform_beside_a_pulley_is_found_by_weight_continuation():
    platform = make_platform(pulleys=True, rigid=True)
    # the direct starts fail here (heavy, deeply sagging right cable); growing the
    # cable weight from zero reaches the equilibrium found by walking to it in 1.7 cm
    # steps: rotation -1.067 rad
    equilibrium = solve_inverse_statics(platform, (-1.4, -2.0))
    assert equilibrium.rotation == pytest.approx(-1.067, abs=1e-3)
    forward = solve_forward_statics(platform, equilibrium.unstrained_lengths)
    np.testing.assert_allclose(forward.position, (-1.4, -2.0), atol=1e-9)  # Newton tolerances


def test_warm_start_along_a_path_gives_the_same_solution():
    platform = make_platform(rigid=True)
    previous = solve_inverse_statics(platform, (0.30, -1.70))
    cold = solve_inverse_statics(platform, (0.31, -1.70))
    warm = solve_inverse_statics(platform, (0.31, -1.70), initial_guess=previous)
    # two Newton runs to the same 1e-12 tolerance from different starts
    np.testing.assert_allclose(warm.unstrained_lengths, cold.unstrained_lengths, rtol=1e-10)
    assert warm.rotation == pytest.approx(cold.rotation, abs=1e-10)


def test_rigid_platform_with_given_rotation_needs_three_cables():
    platform = make_platform(rigid=True)
    third = SuspendedCable(W, EA, anchor=(0.0, -PLATFORM_HEIGHT / 2), exit_point=(1.75, -3.5))
    three = SuspendedPlatform(platform.cables + (third,), mass=2.5)
    equilibrium = solve_inverse_statics(three, (0.2, -1.8), rotation=0.1)
    assert equilibrium.rotation == 0.1
    np.testing.assert_allclose(net_wrench(three, equilibrium), 0.0, atol=1e-9)
    forward = solve_forward_statics(three, equilibrium.unstrained_lengths)
    # three cables hold all three degrees of freedom stiffly: pose to ~1e-12
    np.testing.assert_allclose(forward.position, (0.2, -1.8), atol=1e-9)
    assert forward.rotation == pytest.approx(0.1, abs=1e-9)


# ---------------------------------------------------------------------------
# stiffness and external loads
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("pulleys, rigid", ALL_PLATFORMS)
def test_stiffness_predicts_the_pose_change_under_a_small_extra_load(pulleys, rigid):
    platform = make_platform(pulleys, rigid)
    lengths = solve_inverse_statics(platform, (0.3, -1.8)).unstrained_lengths
    reference = solve_forward_statics(platform, lengths)
    dof = platform.degrees_of_freedom
    step = 1e-4  # [N] or [N m]
    compliance = np.zeros((dof, dof))
    for j in range(dof):
        load = np.zeros(3)
        load[j] = step
        plus = solve_forward_statics(platform, lengths, external_wrench=load)
        minus = solve_forward_statics(platform, lengths, external_wrench=-load)
        pose_plus = np.append(plus.position, plus.rotation)[:dof]
        pose_minus = np.append(minus.position, minus.rotation)[:dof]
        compliance[:, j] = (pose_plus - pose_minus) / (2 * step)
    # central differences of converged equilibria: truncation O(step^2) and solver
    # noise ~1e-12 / 1e-4 relative; 1e-6 of the largest entry covers both
    np.testing.assert_allclose(
        np.linalg.inv(reference.stiffness), compliance, atol=1e-6 * np.abs(compliance).max()
    )
    # a conservative system has a symmetric stiffness (here to the Newton tolerance).
    # With pulleys the model neglects the weight of the wrapped cable, so length moving
    # between wrap and span gains or loses weight: a small non-conservative asymmetry,
    # proportional to w, 2.5e-6 of the stiffness for the paper's cable (0 at w = 0)
    asymmetry = 1e-5 if pulleys else 1e-8
    np.testing.assert_allclose(
        reference.stiffness, reference.stiffness.T, atol=asymmetry * np.abs(reference.stiffness).max()
    )


@pytest.mark.parametrize("rigid", [False, True])
def test_external_wrench_is_balanced_by_the_cables(rigid):
    platform = make_platform(rigid=rigid)
    load = inertial_wrench(platform, acceleration=(1.0, -2.0), angular_acceleration=3.0)
    # d'Alembert: minus mass times acceleration
    np.testing.assert_allclose(load, [-platform.mass, 2 * platform.mass, -0.0271 * 3.0])
    if not rigid:
        load[2] = 0.0
    inverse = solve_inverse_statics(platform, (0.3, -1.7), external_wrench=load)
    np.testing.assert_allclose(net_wrench(platform, inverse), 0.0, atol=1e-9)
    forward = solve_forward_statics(platform, inverse.unstrained_lengths, external_wrench=load)
    np.testing.assert_allclose(forward.position, (0.3, -1.7), atol=1e-9)  # as above
    # the load differs from pure weight, so the lengths must differ too
    plain = solve_inverse_statics(platform, (0.3, -1.7))
    assert np.all(np.abs(plain.unstrained_lengths - inverse.unstrained_lengths) > 1e-4)


# ---------------------------------------------------------------------------
# pulleys
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("position", [(0.0, -1.75), (1.0, -0.6), (-1.3, -2.5)])
def test_cable_leaves_the_pulley_tangentially(position):
    platform = make_platform(pulleys=True)
    equilibrium = solve_inverse_statics(platform, position)
    for cable, spec in zip(equilibrium.cables, platform.cables):
        radius = cable.upper_point - np.array(spec.pulley.center)
        assert np.hypot(*radius) == pytest.approx(PULLEY_RADIUS, rel=1e-14)  # on the rim
        direction = cable.catenary.force_on_b / cable.catenary.tension_b
        # tangency solved to 1e-12 of the length: the direction is normal to the radius
        assert np.dot(direction, radius / PULLEY_RADIUS) == pytest.approx(0.0, abs=1e-10)


def test_pulley_length_counts_the_wrapped_arc_up_to_the_winch_leg():
    platform = make_platform(pulleys=True)
    equilibrium = solve_inverse_statics(platform, (0.0, -1.75))
    for cable in equilibrium.cables:
        wrapped = PULLEY_RADIUS * cable.wrap_angle / (1 + cable.tension_at_exit / EA)
        # sum of two terms: round-off
        assert cable.unstrained_length == pytest.approx(cable.suspended_length + wrapped, rel=1e-14)
        # the cable comes down at about 60 degrees, so it wraps 3/4 of a turn or less
        assert math.pi / 2 < cable.wrap_angle < 3 * math.pi / 4 + 0.3


def test_tiny_pulley_behaves_like_a_fixed_exit_at_its_centre():
    radius = 1e-7
    cables = [
        SuspendedCable(W, EA, pulley=Pulley((sign * PULLEY_X, 0.0), radius, side=sign))
        for sign in (-1, 1)
    ]
    tiny = SuspendedPlatform(cables, mass=1.0)
    with_pulleys = solve_forward_statics(tiny, [2.4, 2.7])
    fixed = solve_forward_statics(make_platform(), [2.4, 2.7])
    # the pulley moves the exit by at most r and adds at most pi r of length: the
    # pose moves by a few r (1e-7 m)
    np.testing.assert_allclose(with_pulleys.position, fixed.position, atol=1e-6)


@pytest.mark.parametrize("pulleys, rigid", ALL_PLATFORMS)
def test_massless_cables_settle_where_straight_elastic_cables_do(pulleys, rigid):
    massive = make_platform(pulleys, rigid)
    cables = [
        SuspendedCable(0.0, EA, anchor=c.anchor, exit_point=c.exit_point, pulley=c.pulley)
        for c in massive.cables
    ]
    massless = SuspendedPlatform(cables, mass=massive.mass)
    lengths = [2.3, 2.6] if not pulleys else [2.9, 3.2]
    position, rotation = straight_cable_pose(massless, lengths)
    equilibrium = solve_forward_statics(massless, lengths)
    # two independent routes to the same equilibrium (energy minimisation with
    # BFGS to 1e-9 of the load, Newton on catenaries with w = 0); the BFGS
    # tolerance over the ~1e4 N/m stiffness bounds the difference
    np.testing.assert_allclose(equilibrium.position, position, atol=1e-9)
    assert equilibrium.rotation == pytest.approx(rotation, abs=1e-7)


# ---------------------------------------------------------------------------
# unreachable
# ---------------------------------------------------------------------------
def test_position_above_the_exits_would_need_pushing_cables():
    with pytest.raises(UnreachableError, match="pulling cables"):
        solve_inverse_statics(make_platform(), (0.0, 0.5))


def test_position_beyond_the_strain_limit_is_unreachable():
    with pytest.raises(UnreachableError):
        solve_inverse_statics(make_platform(), (0.0, -1.75), max_tension=5.0)


# ---------------------------------------------------------------------------
# the paper's scenario 2 (static validation against the catenary)
# ---------------------------------------------------------------------------
def test_paper_scenario_2_settles_symmetric_and_above_the_straight_cable_pose():
    """Point mass M = 1 kg on the straight-cable lengths 1.75 sqrt(2) m from (+-1.75, 0)."""
    platform = make_platform()
    equilibrium = solve_forward_statics(platform, [STRAIGHT_LENGTH, STRAIGHT_LENGTH])
    x, z = equilibrium.position
    assert x == pytest.approx(0.0, abs=1e-12)  # symmetric problem: round-off
    # the cables (8.5 N each, close to the 9.81 N platform) sag a lot, which
    # shortens their chords more than the tension (~1e-4 strain) stretches them:
    # the platform rises above (0, -1.75), by a few centimetres
    assert -1.75 < z < -1.70
    assert equilibrium.is_stable
    # the sagging cable's end tension exceeds the straight massless 6.94 N
    assert np.all(equilibrium.tensions_at_anchor > 6.94)
    # each exit carries half of everything
    top = [c.catenary.force_on_b[1] for c in equilibrium.cables]
    total = platform.mass * platform.gravity + 2 * W * STRAIGHT_LENGTH
    assert -top[0] == pytest.approx(total / 2, rel=1e-10)
    # the inverse problem at the straight-cable point asks for longer cables
    inverse = solve_inverse_statics(platform, (0.0, -1.75))
    assert np.all(inverse.unstrained_lengths > STRAIGHT_LENGTH)


def test_cable_state_at_equilibrium_is_the_catenary_across_its_span():
    platform = make_platform(rigid=True)
    equilibrium = solve_forward_statics(platform, [2.3, 2.7])
    for cable in equilibrium.cables:
        state = solve_forward(
            CABLE.with_length(cable.suspended_length), cable.upper_point - cable.anchor_point
        )
        # the same catenary solved from scratch: to the solver tolerance times stiffness
        np.testing.assert_allclose(state.force_on_a, cable.force_on_platform, atol=1e-7)
