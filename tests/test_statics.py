"""The kineto-static equilibrium of a platform on catenary cables (cdpr_exu.statics.statics), planar and spatial.

Behaviour both dimensions share is one test parametrised over the dimension (PLANAR / SPATIAL cases);
the paper's planar scenario, the pulleys and the spatial robots' own facts have their own tests."""

import math
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.physics.catenary import CatenaryCable, solve_forward
from cdpr_exu.core.errors import SceneError, UnreachableError
import cdpr_exu.statics.statics as statics
from cdpr_exu.core.geometry import left_jacobian, rotation_from_vector
from cdpr_exu.statics.statics import (
    Pulley,
    SuspendedCable,
    SuspendedPlatform,
    forward_cable,
    inertial_wrench,
    solve_inverse_statics,
    solve_statics,
)
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.statics.statics import catenary_platform
from conftest import ASYMMETRIC_LENGTHS, four_cable_robot

# The paper's cable (radius 5 mm, E = 1e9 Pa, 0.35 kg/m) and robot geometry.
CABLE = CatenaryCable(1.0, 0.35 * 9.81, 1e9 * math.pi * 0.005**2)
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
    return SuspendedPlatform(cables, mass=mass, inertia=0.0271)


def is_stable(equilibrium):
    """True when the symmetric part of the equilibrium's stiffness is positive definite."""
    stiffness = equilibrium.stiffness
    return bool(np.all(np.linalg.eigvalsh(0.5 * (stiffness + stiffness.T)) > 0.0))


def net_wrench(platform, equilibrium):
    """Sum of cable forces, weight and external load, and their moment about the centre of mass, recomputed
    from the result: (fx, fz, m) in the plane, (f, m) in space."""
    d = platform.space.position_size
    total = equilibrium.external_wrench.copy()
    total[d - 1] -= platform.mass * platform.gravity
    for cable in equilibrium.cables:
        force = cable.force_on_platform
        arm = cable.anchor_point - equilibrium.position
        total[:d] += force
        total[d:] += arm[0] * force[1] - arm[1] * force[0] if d == 2 else np.cross(arm, force)
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
def test_inverse_statics_must_be_square():
    with pytest.raises(SceneError, match="as many unknowns as equations"):
        solve_inverse_statics(make_platform(rigid=True), (0, -1.5, 0.0))
    with pytest.raises(SceneError, match="no rotation"):
        solve_inverse_statics(make_platform(), (0, -1.5, 0.3))


# ---------------------------------------------------------------------------
# point mass
# ---------------------------------------------------------------------------
def test_point_mass_in_the_symmetric_middle_hangs_on_equal_tensions():
    platform = make_platform()
    equilibrium = solve_inverse_statics(platform, (0.0, -1.75))
    tensions = equilibrium.tensions_at_anchor
    # mirror-symmetric problem solved by the same Newton steps: round-off only
    assert tensions[0] == pytest.approx(tensions[1], rel=1e-12)
    forces = np.array([c.force_on_platform for c in equilibrium.cables])
    # the vertical components carry the weight, the horizontal ones cancel;
    # the Newton tolerance is 1e-12 of the load
    assert forces[:, 1].sum() == pytest.approx(platform.mass * platform.gravity, rel=1e-11)
    assert forces[:, 0].sum() == pytest.approx(0.0, abs=1e-10)
    # the sagging cable meets the platform less steeply than the straight 45 degrees,
    # so its tension exceeds the massless Mg / (2 sin 45) = 6.94 N
    assert tensions[0] > platform.mass * platform.gravity / math.sqrt(2)


@pytest.mark.parametrize("pulleys, rigid", ALL_PLATFORMS)
def test_inverse_statics_of_the_forward_returns_the_lengths(pulleys, rigid):
    platform = make_platform(pulleys, rigid)
    lengths = [2.3, 2.9] if not pulleys else [2.9, 3.5]
    forward = solve_statics(platform, lengths)
    inverse = solve_inverse_statics(platform, forward.position)
    # lengths inherit the forward pose error (~1e-12 m) times a gain of order 1
    np.testing.assert_allclose(inverse.unstrained_lengths, lengths, rtol=1e-9)


def test_forward_statics_finds_a_pendulum_pulled_aside_by_a_slack_heavy_cable():
    """Near-vertical stiff cable plus a long sagging one: a curved, ill-conditioned valley."""
    platform = make_platform()
    lengths = solve_inverse_statics(platform, (-1.4, -1.85)).unstrained_lengths
    assert lengths[1] > 2 * lengths[0]  # the right cable hangs in a deep sag
    equilibrium = solve_statics(platform, lengths)
    # stiffness ratio ~1e4 between along and across the left cable; the pose is
    # still found to the Newton tolerance over the soft stiffness (~10 N/m)
    np.testing.assert_allclose(equilibrium.position, (-1.4, -1.85), atol=1e-9)


def test_platform_weight_and_cable_weight_hang_on_the_exits():
    platform = make_platform()
    equilibrium = solve_statics(platform, [2.4, 2.6])
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
    assert is_stable(equilibrium)
    np.testing.assert_allclose(net_wrench(platform, equilibrium), 0.0, atol=1e-9)  # Newton tolerance


def test_rigid_platform_beside_a_pulley_is_found_by_weight_continuation():
    platform = make_platform(pulleys=True, rigid=True)
    # the direct starts fail here (heavy, deeply sagging right cable); growing the
    # cable weight from zero reaches the equilibrium found by walking to it in 1.7 cm
    # steps: rotation -1.067 rad
    equilibrium = solve_inverse_statics(platform, (-1.4, -2.0))
    assert equilibrium.rotation == pytest.approx(-1.067, abs=1e-3)
    forward = solve_statics(platform, equilibrium.unstrained_lengths)
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
    equilibrium = solve_inverse_statics(three, (0.2, -1.8, 0.1))
    assert equilibrium.rotation == 0.1
    np.testing.assert_allclose(net_wrench(three, equilibrium), 0.0, atol=1e-9)
    forward = solve_statics(three, equilibrium.unstrained_lengths)
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
    reference = solve_statics(platform, lengths)
    dof = platform.degrees_of_freedom
    step = 1e-4  # [N] or [N m]
    compliance = np.zeros((dof, dof))
    for j in range(dof):
        load = np.zeros(3)
        load[j] = step
        plus = solve_statics(platform, lengths, external_wrench=load)
        minus = solve_statics(platform, lengths, external_wrench=-load)
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
    forward = solve_statics(platform, inverse.unstrained_lengths, external_wrench=load)
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
        radius = cable.exit_point - np.array(spec.pulley.center)
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
    with_pulleys = solve_statics(tiny, [2.4, 2.7])
    fixed = solve_statics(make_platform(), [2.4, 2.7])
    # the pulley moves the exit by at most r and adds at most pi r of length: the
    # pose moves by a few r (1e-7 m)
    np.testing.assert_allclose(with_pulleys.position, fixed.position, atol=1e-6)


# ---------------------------------------------------------------------------
# shared by both dimensions
# ---------------------------------------------------------------------------
SPACES = [pytest.param(2, id="planar"), pytest.param(3, id="spatial")]
PLATFORM_HALF = 0.1  # the four-cable robot's anchors are 0.1 m from its axis


def robot(dimension, rigid=True, pulleys=False):
    """The planar paper robot (tests above) or the spatial four-cable robot (tests/conftest.py)."""
    return make_platform(pulleys, rigid) if dimension == 2 else four_cable_robot(rigid)


def one_cable(dimension, **changes):
    fields = dict(weight_per_length=W, axial_stiffness=EA, exit_point=(1.75, 0.0) if dimension == 2 else (1.5, 1.5, 0.0))
    fields.update(changes)
    return SuspendedCable(**fields)


def _in(dimension, planar, spatial):
    return planar if dimension == 2 else spatial


@pytest.mark.parametrize("dimension", SPACES)
@pytest.mark.parametrize("changes, field", [
    ({"weight_per_length": -1.0}, "weight_per_length"),
    ({"axial_stiffness": 0.0}, "axial_stiffness"),
    ({"axial_stiffness": float("nan")}, "axial_stiffness"),
    ({"exit_point": {2: (1.0, float("nan")), 3: (1.0, float("nan"), 0.0)}}, "exit_point"),
    ({"exit_point": (1.0, 0.0, 0.0, 0.0)}, "exit_point"),
    ({"anchor": {2: (0.0, float("inf")), 3: (0.0, float("inf"), 0.0)}}, "anchor"),
    ({"anchor": {2: (0.0, 0.0, 0.0), 3: (0.0, 0.0)}}, "anchor"),
    ({"exit_point": None}, "exactly one of exit_point and pulley"),
])
def test_a_bad_cable_is_refused_naming_the_field(dimension, changes, field):
    changes = {k: v[dimension] if isinstance(v, dict) else v for k, v in changes.items()}
    with pytest.raises(SceneError, match=field):
        one_cable(dimension, **changes)


def test_a_bad_planar_pulley_is_refused_naming_the_field():
    with pytest.raises(SceneError, match="radius"):
        Pulley((0, 0), -0.2)
    with pytest.raises(SceneError, match="side"):
        Pulley((0, 0), 0.2, side=0)


@pytest.mark.parametrize("dimension", SPACES)
def test_a_bad_platform_is_refused_naming_the_field(dimension):
    good = list(robot(dimension).cables)
    with pytest.raises(SceneError, match="mass"):
        SuspendedPlatform(good, mass=-1.0)
    with pytest.raises(SceneError, match="mass"):
        SuspendedPlatform(good, mass=float("nan"))
    with pytest.raises(SceneError, match="inertia"):
        SuspendedPlatform(good, mass=1.0, inertia=_in(dimension, -0.1, (0.1, -0.1, 0.1)))
    with pytest.raises(SceneError, match="exit_point"):
        SuspendedPlatform([good[0], one_cable(dimension, exit_point=good[0].exit_point,
                                              anchor=_in(dimension, (0.0, 0.1), (0.0, 0.1, 0.0)))], mass=1.0)
    with pytest.raises(SceneError, match="anchor"):
        SuspendedPlatform([good[0], one_cable(dimension, exit_point=_in(dimension, (9.0, 0.0), (9.0, 0.0, 0.0)),
                                              anchor=good[0].anchor)], mass=1.0)
    with pytest.raises(SceneError, match="cables"):
        SuspendedPlatform([], mass=1.0)
    with pytest.raises(SceneError, match="cables"):
        SuspendedPlatform([good[0]], mass=1.0)  # a rigid body on one cable turns freely about it
    with pytest.raises(SceneError, match="cables"):
        SuspendedPlatform(["not a cable"], mass=1.0)
    with pytest.raises(SceneError, match="cables must all be planar or all spatial"):
        SuspendedPlatform([good[0], robot(5 - dimension).cables[1]], mass=1.0)


def test_a_spatial_platform_whose_anchors_lie_on_one_line_through_its_centre_is_refused():
    with pytest.raises(SceneError, match="cables"):
        SuspendedPlatform([one_cable(3, anchor=(0.1, 0.0, 0.0)),
                           one_cable(3, exit_point=(-1.5, 0, 0), anchor=(-0.1, 0.0, 0.0))], mass=1.0)


@pytest.fixture
def no_solve(monkeypatch):
    """Fail the test if a catenary or the starting pose is ever solved."""

    def forbidden(*args, **kwargs):
        raise AssertionError("a solve started before the input was refused")

    monkeypatch.setattr(statics, "forward_cable", forbidden)
    monkeypatch.setattr(statics, "minimize", forbidden)


@pytest.mark.parametrize("dimension", SPACES)
@pytest.mark.parametrize("last", [None, -1.0, float("nan")], ids=["count", "negative", "nan"])
def test_bad_lengths_are_refused_before_any_solve(no_solve, dimension, last):
    platform = robot(dimension, rigid=False)
    lengths = [2.5] * (len(platform.cables) - 1) + ([] if last is None else [last])
    with pytest.raises(SceneError, match="unstrained_lengths"):
        solve_statics(platform, lengths)


@pytest.mark.parametrize("dimension, lengths, pair", [
    pytest.param(2, [1.4, 1.5], r"cables\[0\] and cables\[1\]", id="planar"),  # 3.5 m apart, reach 3.19 m
    # opposite exits are 4.24 m apart; two 1.9 m cables reach 4.18 m at 10 % strain
    pytest.param(3, [1.9, 2.5, 1.9, 2.5], r"cables\[0\] and cables\[2\]", id="spatial"),
])
def test_cables_that_cannot_both_reach_the_platform_are_refused_before_any_solve(no_solve, dimension, lengths, pair):
    with pytest.raises(UnreachableError, match=rf"unstrained_lengths: {pair} cannot both reach"):
        solve_statics(robot(dimension, rigid=False), lengths)


@pytest.mark.parametrize("dimension", SPACES)
def test_bad_options_are_refused_before_any_solve(no_solve, dimension):
    platform = robot(dimension)
    lengths = _in(dimension, [2.3, 2.7], [2.5] * 4)
    with pytest.raises(SceneError, match="initial_pose"):
        solve_statics(platform, lengths, initial_pose=[0.0, 0.0, -1.0, 0.0])
    with pytest.raises(SceneError, match="external_wrench"):
        solve_statics(platform, lengths, external_wrench=[0.0, 1.0])
    with pytest.raises(SceneError, match="max_strain"):
        solve_statics(platform, lengths, max_strain=0.0)
    with pytest.raises(SceneError, match="platform"):
        solve_statics("platform", lengths)
    with pytest.raises(SceneError, match="external_wrench"):
        solve_inverse_statics(platform, _in(dimension, (0, -1.5), [0.0, 0.0, -1.5] + [0.0] * 3),
                              external_wrench=(1.0, 2.0), initial_guess=np.full(len(lengths), 10.0))


@pytest.mark.parametrize("dimension", SPACES)
def test_no_equilibrium_within_the_tension_limit_is_a_clear_error(dimension):
    # short cables: the platform can only hang from them at tensions far above the limit
    with pytest.raises(UnreachableError, match="no equilibrium found for unstrained_lengths"):
        solve_statics(robot(dimension, rigid=False), _in(dimension, [2.5, 2.5], [2.3] * 4),
                      max_tension=_in(dimension, 2.0, 10.0))


ROUND_TRIPS = ([pytest.param(2, p.values, position, id=f"planar-{p.id}-{position}") for p in ALL_PLATFORMS
                for position in [(0.0, -1.75), (0.5, -1.5), (-0.9, -2.2), (1.2, -0.8)]]
               + [pytest.param(3, name, None, id=name) for name in ("spatial-cogiro", "spatial-ipanema")])


@pytest.mark.parametrize("dimension, platform_kind, target", ROUND_TRIPS)
def test_forward_statics_of_the_inverse_lengths_returns_the_pose(dimension, platform_kind, target):
    if dimension == 2:
        platform, guess, start = make_platform(*platform_kind), None, None
    else:
        scene = load_scene(platform_kind)
        platform = catenary_platform(scene)
        rest = solve_statics(platform, scene.unstrained_lengths)
        target = np.append(rest.position, rest.rotation) + np.array([0.1, -0.05, 0.02, 0.0, 0.0, 0.02])
        guess = start = rest.horizontal_tensions
    inverse = solve_inverse_statics(platform, target, initial_guess=guess)
    forward = solve_statics(platform, inverse.unstrained_lengths, initial_pose=None if start is None else target)
    # both solves stop at 1e-12 of the load (planar Newton; spatial Gauss-Newton to 1e-9 of the weight);
    # the pose error is that over the stiffness (>= ~1e2 N/m), far below 1e-9 m (measured 5e-12 m and
    # rad for both spatial robots)
    np.testing.assert_allclose(forward.position, np.asarray(target)[:platform.space.position_size], atol=1e-9)
    np.testing.assert_allclose(forward.rotation, inverse.rotation, atol=1e-9)
    assert is_stable(forward)


def test_the_spatial_inverse_at_the_rest_gives_back_the_lengths_and_stays_near_the_start_tensions():
    for name in ("spatial-cogiro", "spatial-ipanema"):
        scene = load_scene(name)
        platform = catenary_platform(scene)
        rest = solve_statics(platform, scene.unstrained_lengths)
        tensions = rest.horizontal_tensions
        # at the rest pose, with the rest's tensions: the scene's own lengths come back
        rest_pose = np.append(rest.position, rest.rotation)
        back = solve_inverse_statics(platform, rest_pose, initial_guess=tensions)
        np.testing.assert_allclose(back.unstrained_lengths, scene.unstrained_lengths, atol=1e-9)
        # elsewhere the tensions stay nearest the start: an over-constrained robot keeps its internal tension
        target = np.append(rest.position, rest.rotation) + np.array([0.1, -0.05, 0.02, 0.0, 0.0, 0.02])
        inverse = solve_inverse_statics(platform, target, initial_guess=back)
        assert np.abs(inverse.horizontal_tensions - tensions).max() < 0.5 * tensions.max()


#: The planar robot with and without pulleys, rigid or a point mass; the spatial four-cable robot, rigid or not.
BOTH_SPACES = ([pytest.param(2, p.values, id=f"planar-{p.id}") for p in ALL_PLATFORMS]
               + [pytest.param(3, (False, rigid), id=f"spatial-{'rigid' if rigid else 'point-mass'}")
                  for rigid in (False, True)])


@pytest.mark.parametrize("dimension, platform_kind", BOTH_SPACES)
def test_cable_forces_balance_the_weight_and_their_moments_cancel(dimension, platform_kind):
    pulleys, rigid = platform_kind
    platform = robot(dimension, rigid, pulleys)
    weight = platform.mass * platform.gravity
    if dimension == 2:
        solved = (solve_inverse_statics(platform, (0.4, -1.6)), solve_statics(platform, [2.2, 2.8] if not pulleys else [2.8, 3.4]))
        # Newton tolerance 1e-12 of the ~40 N load (1e-11 in the moment's N m)
        force_tolerance = moment_tolerance = 1e-9
    else:
        solved = (solve_statics(platform, ASYMMETRIC_LENGTHS),)
        # the solver's noise floor: 1e-9 (1 + EA / weights) relative, 2e-6 of the 80 N of weights here
        force_tolerance, moment_tolerance = 1e-7 * weight, 1e-7 * weight * PLATFORM_HALF
    for equilibrium in solved:
        residual = net_wrench(platform, equilibrium)
        d = platform.space.position_size
        assert np.abs(residual[:d]).max() < force_tolerance
        assert np.abs(residual[d:]).max() < moment_tolerance
        np.testing.assert_allclose(equilibrium.net_wrench, residual, atol=max(force_tolerance, moment_tolerance))
        # each cable's two end forces carry the weight of its suspended part
        for cable in equilibrium.cables:
            total = cable.force_on_platform + cable.force_on_exit
            expected = np.zeros(d)
            expected[-1] = -W * cable.suspended_length
            np.testing.assert_allclose(total, expected, atol=1e-9)
        assert is_stable(equilibrium)
    if dimension == 3 and rigid:
        assert np.linalg.norm(solved[0].rotation) > 1e-2  # it does turn


@pytest.mark.parametrize("dimension, platform_kind", BOTH_SPACES)
def test_massless_cables_settle_where_straight_elastic_cables_do(dimension, platform_kind):
    pulleys, rigid = platform_kind
    massive = robot(dimension, rigid, pulleys)
    cables = [SuspendedCable(0.0, c.axial_stiffness, anchor=c.anchor, exit_point=c.exit_point, pulley=c.pulley)
              for c in massive.cables]
    massless = SuspendedPlatform(cables, mass=massive.mass, inertia=massive.inertia)
    lengths = [2.3, 2.6] if not pulleys else [2.9, 3.2]
    lengths = lengths if dimension == 2 else ASYMMETRIC_LENGTHS
    # the start of solve_statics: the pose on straight, massless, elastic cables
    straight = statics._KERNELS[massless.space].straight_cable_pose(massless, np.array(lengths, dtype=float),
                                                                    np.zeros(massless.space.wrench_size))
    equilibrium = solve_statics(massless, lengths)
    # two independent routes to the same equilibrium (energy minimisation with BFGS to 1e-9 of the
    # load, Newton on catenaries with w = 0); the BFGS tolerance over the stiffness bounds the difference
    # (measured in space: 2e-10 m and 4e-9 rad on the rigid four-cable robot)
    d = massless.space.position_size
    np.testing.assert_allclose(equilibrium.position, straight[:d], atol=1e-9)
    np.testing.assert_allclose(equilibrium.rotation, straight[d:] if dimension == 3 else straight[d], atol=1e-7)


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
    equilibrium = solve_statics(platform, [STRAIGHT_LENGTH, STRAIGHT_LENGTH])
    x, z = equilibrium.position
    assert x == pytest.approx(0.0, abs=1e-12)  # symmetric problem: round-off
    # the cables (8.5 N each, close to the 9.81 N platform) sag a lot, which
    # shortens their chords more than the tension (~1e-4 strain) stretches them:
    # the platform rises above (0, -1.75), by a few centimetres
    assert -1.75 < z < -1.70
    assert is_stable(equilibrium)
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
    equilibrium = solve_statics(platform, [2.3, 2.7])
    for cable in equilibrium.cables:
        state = solve_forward(
            replace(CABLE, unstrained_length=cable.suspended_length), cable.exit_point - cable.anchor_point
        )
        # the same catenary solved from scratch: to the solver tolerance times stiffness
        np.testing.assert_allclose(state.force_on_a, cable.force_on_platform, atol=1e-7)


# ---------------------------------------------------------------------------
# spatial robots
# ---------------------------------------------------------------------------
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
    spatial = SuspendedPlatform([SuspendedCable(W, EA, anchor=anchor[0] * along + [0, 0, anchor[1]],
                                                exit_point=sign * 1.75 * along)
                                 for sign, anchor in zip((-1, 1), planar_anchors)], mass=2.5, inertia=(0.1,) * 3)
    lengths = [2.45, 2.5]
    expected = solve_statics(planar, lengths)
    found = solve_statics(spatial, lengths)
    # Both solvers stop at a scaled residual of 1e-12 (or the 1e3 x noise floor of the
    # stiff cables, 2e-6 N on 30 N): the poses agree to 1e-9 m, the tensions to 1e-7 N
    # (measured: 1.2e-13 m, 1e-16 rad, 2e-10 N).
    np.testing.assert_allclose(found.position @ along, expected.position[0], atol=1e-9)
    np.testing.assert_allclose(found.position[2], expected.position[1], atol=1e-9)
    normal = np.cross(along, [0.0, 0.0, 1.0])
    assert abs(found.position @ normal) < 1e-12
    # the planar rotation phi turns ``along`` towards +z: about the axis along x e_z
    np.testing.assert_allclose(found.rotation, expected.rotation * np.cross(along, [0.0, 0.0, 1.0]), atol=1e-9)
    np.testing.assert_allclose(found.tensions_at_anchor, expected.tensions_at_anchor, atol=1e-7)
    np.testing.assert_allclose([c.tension_at_exit for c in found.cables],
                               [c.tension_at_exit for c in expected.cables], atol=1e-7)


# ---------------------------------------------------------------------------
# 2. symmetry
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("rigid", BOTH)
def test_symmetric_four_cable_robot_hangs_on_the_axis_with_equal_tensions_and_no_rotation(rigid):
    platform = four_cable_robot(rigid)
    equilibrium = solve_statics(platform, [2.5] * 4)
    # the solve is a Newton iteration to a scaled residual of 1e-12: symmetry holds to round-off
    np.testing.assert_allclose(equilibrium.position[:2], 0.0, atol=1e-12)
    np.testing.assert_allclose(equilibrium.rotation, 0.0, atol=1e-12)
    tensions = equilibrium.tensions_at_anchor
    np.testing.assert_allclose(tensions, tensions.mean(), rtol=1e-12)
    # each cable carries a quarter of the weight at its anchor
    vertical = [c.force_on_platform[2] for c in equilibrium.cables]
    np.testing.assert_allclose(vertical, platform.mass * platform.gravity / 4, rtol=1e-10)
    assert is_stable(equilibrium)


@pytest.mark.parametrize("rigid", BOTH)
def test_stiffness_is_minus_the_derivative_of_the_generalised_force(rigid):
    platform = four_cable_robot(rigid)
    equilibrium = solve_statics(platform, ASYMMETRIC_LENGTHS)
    dof = platform.degrees_of_freedom
    x0 = np.concatenate([equilibrium.position, equilibrium.rotation])[:dof]

    def generalised_force(x):
        theta = x[3:] if dof == 6 else np.zeros(3)
        rotation = rotation_from_vector(theta)
        force, moment = np.array([0.0, 0.0, -platform.mass * platform.gravity]), np.zeros(3)
        for cable, length in zip(platform.cables, ASYMMETRIC_LENGTHS):
            arm = rotation @ np.array(cable.anchor)
            cable_equilibrium, _ = forward_cable(cable, length, x[:3] + arm)
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
    cables[0] = SuspendedCable(W, 4 * EA, exit_point=cables[0].exit_point)
    stiff = SuspendedPlatform(cables, mass=soft.mass)
    lengths = [2.5] * 4
    base = solve_statics(soft, lengths).tensions_at_anchor
    equilibrium = solve_statics(stiff, lengths)
    changed = equilibrium.tensions_at_anchor
    # measured: the stiff cable's diagonal (0, 2) takes 1.7 % more, the other diagonal 1.6 % less
    assert changed[0] > base[0] * 1.01 and changed[2] > base[2] * 1.01
    assert changed[1] < base[1] * 0.99 and changed[3] < base[3] * 0.99
    assert equilibrium.position[0] > 0.0 and equilibrium.position[1] > 0.0  # towards the stiff cable's exit
    force = net_wrench(stiff, equilibrium)[:3]
    assert np.abs(force).max() < 1e-7 * stiff.mass * stiff.gravity  # the noise floor, as above


def test_a_cable_profile_starts_at_the_anchor_and_ends_at_the_exit():
    equilibrium = solve_statics(four_cable_robot(True), ASYMMETRIC_LENGTHS)
    for cable in equilibrium.cables:
        points = cable.points([0.0, cable.unstrained_length])
        # the closed-form profile of a span solved to 1e-12 of the length
        np.testing.assert_allclose(points[0], cable.anchor_point, atol=1e-12)
        np.testing.assert_allclose(points[1], cable.exit_point, atol=1e-10)


def test_the_inverse_refuses_a_pose_only_a_pushing_cable_could_hold():
    platform = four_cable_robot(rigid=False)
    with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace|did not converge"):
        solve_inverse_statics(platform, [0.0, 0.0, 0.5], initial_guess=np.full(4, 10.0))  # above the exits
