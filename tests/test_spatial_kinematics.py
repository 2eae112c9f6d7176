"""Ideal kinematics and statics of spatial robots (cdpr_exu.physics.spatial_kinematics): pure maths, no Exudyn."""

import math

import numpy as np
import pytest
from scipy.optimize import linprog, minimize

from cdpr_exu.statics import kinematics as planar
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import left_jacobian
from cdpr_exu.physics import cogiro
from cdpr_exu.core.geometry import swivel_pulley_exit
from cdpr_exu.exits import PointExit, Pulley, Swivel
from cdpr_exu.scenes.scene import PlatformSpec, Scene
from cdpr_exu.physics.spatial_kinematics import (IdealSpatialRobot, cable_unit_vectors, gravity_wrench,
                                                 inverse_kinematics, inverse_kinematics_rates, structure_matrix,
                                                 tension_distribution)

# The paper's planar robot (as tests/test_kinematics.py)
PLANAR_CENTERS = np.array([[-1.75, 0.0], [1.75, 0.0]])
PLANAR_RADIUS = 0.25
PLANAR_SIDES = np.array([-1, 1])
PLANAR_ANCHORS = np.array([[-0.15, 0.1], [0.15, 0.1]])
PLANAR_POSES = np.array([[0.0, -2.0, 0.0], [0.3, -1.4, 0.2], [-0.5, -2.5, -0.3], [0.1, -0.8, 0.05]])

# CoGiRo as published in CASPR (cdpr_exu/physics/cogiro.py cites the files), with swivel pulleys of 0.1 m added
# where a test exercises the pulley geometry (CASPR's own cables have point exits).
SWIVEL_RADIUS = 0.1
COGIRO = IdealSpatialRobot(cogiro.EXIT_POINTS, cogiro.ANCHORS, 0.0, cogiro.MASS, cogiro.MIN_TENSION,
                           cogiro.MAX_TENSION, cogiro.CENTER_OF_MASS)
COGIRO_SWIVEL = IdealSpatialRobot(cogiro.EXIT_POINTS, cogiro.ANCHORS, SWIVEL_RADIUS, cogiro.MASS,
                                  cogiro.MIN_TENSION, cogiro.MAX_TENSION, cogiro.CENTER_OF_MASS)
# Positions of CASPR's CoGiRo_trajectories.xml (the "long_stable" way points), here with and without rotation.
COGIRO_POSES = np.array([
    [0.0, 0.0, 2.0, 0.0, 0.0, 0.0],
    [-3.0, -1.0, 2.0, 0.0, 0.0, 0.0],
    [2.0, -3.0, 0.0, 0.0, 0.0, 0.0],
    [2.0, 0.0, 2.0, 0.0, 0.0, 0.0],
    [-4.0, 1.0, 0.0, 0.0, 0.0, 0.0],
    [2.0, -3.0, 4.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 2.0, 0.1, -0.05, 0.2],
    [-2.0, 2.0, 2.0, -0.1, 0.05, -0.3],
])
GENERAL_POSE = np.array([1.2, -0.7, 2.3, 0.15, -0.1, 0.25])
GENERAL_RATE = np.array([0.3, -0.2, 0.5, 0.4, -0.3, 0.6])


def plane_embedding(azimuth, origin=(0.4, -0.3, 1.1)):
    """The vertical plane of the planar model (x, z) in 3-D: origin, in-plane axes e1 (horizontal), e3 = e_z, normal."""
    e1 = np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    e3 = np.array([0.0, 0.0, 1.0])
    normal = np.cross(e1, e3)  # a planar counter-clockwise rotation phi is the rotation vector phi * normal
    return np.asarray(origin), e1, e3, normal


def embedded_robot(azimuth):
    """The paper's planar robot placed in the vertical plane of the given azimuth: poses, anchors, inlets."""
    origin, e1, e3, normal = plane_embedding(azimuth)
    hang = np.array([Pulley(c, PLANAR_RADIUS, s).hang_point for c, s in zip(PLANAR_CENTERS, PLANAR_SIDES)])
    inlets = origin + hang[:, :1] * e1 + hang[:, 1:] * e3
    anchors = PLANAR_ANCHORS[:, :1] * e1 + PLANAR_ANCHORS[:, 1:] * e3  # platform frame = world at theta = 0
    poses = np.hstack([origin + PLANAR_POSES[:, :1] * e1 + PLANAR_POSES[:, 1:2] * e3,
                       PLANAR_POSES[:, 2:] * normal])
    return poses, anchors, inlets


def symmetric_robot(point_mass=False):
    """8 cables (4 on a point mass), mirror-symmetric in x and in y, frame 15 x 11 x 5.5 m, 91 kg, 100-5000 N."""
    inlets, anchors = [], []
    for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        inlets.append((sx * 7.5, sy * 5.2, 5.5))
        anchors.append((sx * 0.5, sy * 0.5, 0.0))
        if not point_mass:
            inlets.append((sx * 7.2, sy * 5.5, 5.5))
            anchors.append((sx * 0.5, sy * 0.35, 1.0))
    return IdealSpatialRobot(np.array(inlets), None if point_mass else np.array(anchors), SWIVEL_RADIUS, 91.0,
                             100.0, 5000.0, (0.0, 0.0, 0.5))


# ----------------------------------------------------------------------------------
# the swivel pulley
# ----------------------------------------------------------------------------------
@pytest.mark.parametrize("azimuth", [0.0, 0.7, 2.0, -2.5])
def test_robot_in_a_vertical_plane_reproduces_planar_kinematics(azimuth):
    poses, anchors, inlets = embedded_robot(azimuth)
    _, e1, e3, normal = plane_embedding(azimuth)
    robot = Scene(exits=tuple(Pulley(c, PLANAR_RADIUS, s) for c, s in zip(PLANAR_CENTERS, PLANAR_SIDES)),
                  platform=PlatformSpec(anchors=PLANAR_ANCHORS))  # the planar robot, its kinematics its exits'
    # Round-off: lengths of about 2 m computed in different frames (a rotation of the plane, Rodrigues'
    # formula for the platform): a few 1e-16 relative; 1e-13 leaves a hundredfold margin, far below any geometry.
    np.testing.assert_allclose(inverse_kinematics(poses, anchors, inlets, PLANAR_RADIUS),
                               planar.ideal_paid_out(robot, PLANAR_POSES)[0], rtol=0, atol=1e-13)
    units = cable_unit_vectors(poses, anchors, inlets, PLANAR_RADIUS)
    planar_units = -np.stack([e.unit_vector for e in planar.cable_exits(robot, PLANAR_POSES)], axis=-2)
    np.testing.assert_allclose(units, planar_units[..., :1] * e1 + planar_units[..., 1:] * e3, rtol=0, atol=1e-13)
    matrix = structure_matrix(poses, anchors, units)
    planar_matrix = planar.structure_matrix(PLANAR_POSES, PLANAR_ANCHORS, planar_units)
    in_plane = np.stack([np.einsum("k,nkm->nm", e1, matrix[:, :3]), np.einsum("k,nkm->nm", e3, matrix[:, :3]),
                         np.einsum("k,nkm->nm", normal, matrix[:, 3:])], axis=1)
    np.testing.assert_allclose(in_plane, planar_matrix, rtol=0, atol=1e-13)
    # nothing out of the plane: no force along its normal, no moment about an in-plane axis
    np.testing.assert_allclose(np.einsum("k,nkm->nm", normal, matrix[:, :3]), 0.0, atol=1e-13)
    np.testing.assert_allclose(np.einsum("k,nkm->nm", e1, matrix[:, 3:]), 0.0, atol=1e-13)
    np.testing.assert_allclose(np.einsum("k,nkm->nm", e3, matrix[:, 3:]), 0.0, atol=1e-13)
    # the wrap angles are the planar ones
    origin = plane_embedding(azimuth)[0]
    points = planar.anchor_points(PLANAR_POSES, PLANAR_ANCHORS)
    for i in range(2):
        planar_exit = planar.pulley_exit(PLANAR_CENTERS[i], PLANAR_RADIUS, PLANAR_SIDES[i], points[:, i])
        spatial_points = origin + points[:, i, :1] * e1 + points[:, i, 1:] * e3
        swivel = swivel_pulley_exit(inlets[i], PLANAR_RADIUS, spatial_points)
        np.testing.assert_allclose(swivel.wrap_angle, planar_exit.wrap_angle, rtol=0, atol=1e-13)


def test_zero_radius_gives_the_point_exit_length():
    rng = np.random.default_rng(1)
    inlet = np.array([1.0, -2.0, 5.0])
    anchors = inlet + rng.uniform(-4.0, 4.0, size=(50, 3))
    distance = np.linalg.norm(anchors - inlet, axis=1)
    # r_p = 0 is the point exit itself: exact up to the square root's rounding
    np.testing.assert_allclose(swivel_pulley_exit(inlet, 0.0, anchors).cable_length, distance, rtol=1e-15)
    # r_p -> 0 tends to it linearly: |L - |p - e|| <= r_p (3 pi / 2 + 1) (the arc plus the shift of the tangent point)
    for radius in (1e-3, 1e-6, 1e-9):
        gap = np.abs(swivel_pulley_exit(inlet, radius, anchors).cable_length - distance)
        assert np.all(gap <= radius * (1.5 * math.pi + 1.0))


def test_tangent_point_is_on_the_rim_in_the_anchors_vertical_plane_and_the_free_cable_is_tangent():
    rng = np.random.default_rng(2)
    inlet, radius = np.array([0.0, 0.0, 5.0]), 0.3
    anchors = inlet + np.column_stack([rng.uniform(-5, 5, 40), rng.uniform(-5, 5, 40), rng.uniform(-6, 2, 40)])
    exit_ = swivel_pulley_exit(inlet, radius, anchors)
    e_rho = np.column_stack([np.cos(exit_.azimuth), np.sin(exit_.azimuth), np.zeros(40)])
    np.testing.assert_allclose(exit_.azimuth, np.arctan2(anchors[:, 1], anchors[:, 0]), atol=1e-15)
    center = inlet + radius * e_rho
    radial = exit_.tangent_point - center
    # lengths of a few metres: round-off of a few 1e-15 m
    np.testing.assert_allclose(np.linalg.norm(radial, axis=1), radius, atol=1e-14)
    np.testing.assert_allclose(np.einsum("ij,ij->i", radial, exit_.unit_vector), 0.0, atol=1e-14)
    normal = np.cross(e_rho, [0.0, 0.0, 1.0])  # the disc's plane contains e_rho and e_z
    np.testing.assert_allclose(np.einsum("ij,ij->i", exit_.tangent_point - inlet, normal), 0.0, atol=1e-14)
    np.testing.assert_allclose(exit_.tangent_point + exit_.free_length[:, None] * exit_.unit_vector, anchors,
                               atol=1e-13)
    assert np.all((exit_.wrap_angle >= 0.0) & (exit_.wrap_angle < 1.5 * math.pi))


def test_anchor_on_the_swivel_axis_keeps_the_previous_azimuth_or_is_refused():
    pulley = Swivel((0.0, 0.0, 5.0), 0.2)
    below = np.array([0.0, 0.0, 1.0])
    with pytest.raises(UnreachableError, match="axis of the swivel pulley"):
        pulley.exit(below)
    hinted = pulley.exit(below, azimuth_hint=0.5)
    assert hinted.azimuth == 0.5
    # a trajectory passing under the pulley keeps the azimuth it had just before
    path = np.array([[0.3, 0.3, 1.0], below, [-0.3, -0.3, 1.0]])
    exit_ = pulley.exit(path)
    assert exit_.azimuth[1] == exit_.azimuth[0] == pytest.approx(math.pi / 4)
    # its length does not depend on the azimuth: the planar cable to (0, -4) in the disc's plane
    np.testing.assert_allclose(hinted.cable_length, exit_.cable_length[1], rtol=1e-15)
    # a point exit needs no azimuth: the cable is vertical
    np.testing.assert_allclose(PointExit((0.0, 0.0, 5.0)).exit(below).unit_vector, [0, 0, -1], atol=0)


def test_anchor_inside_the_disc_is_refused():
    with pytest.raises(UnreachableError, match="inside the disc"):
        swivel_pulley_exit((0.0, 0.0, 5.0), 0.2, (0.2, 0.0, 5.05))


# ----------------------------------------------------------------------------------
# rates and the structure matrix
# ----------------------------------------------------------------------------------
@pytest.mark.parametrize("robot", [COGIRO, COGIRO_SWIVEL], ids=["point exits", "swivel pulleys"])
def test_length_rates_match_central_differences_of_the_lengths(robot):
    step = 1e-6
    numeric = (robot.lengths(GENERAL_POSE + step * GENERAL_RATE)
               - robot.lengths(GENERAL_POSE - step * GENERAL_RATE)) / (2.0 * step)
    # Central differences: truncation ~ step^2 |L'''| ~ 1e-12, round-off ~ 1e-16 * 10 m / step = 1e-9 m/s.
    np.testing.assert_allclose(robot.length_rates(GENERAL_POSE, GENERAL_RATE), numeric, rtol=0, atol=1e-8)


def test_point_mass_length_rates_match_central_differences():
    robot, position, rate, step = symmetric_robot(point_mass=True), np.array([1.0, -2.0, 2.5]), \
        np.array([0.4, 0.3, -0.2]), 1e-6
    numeric = (robot.lengths(position + step * rate) - robot.lengths(position - step * rate)) / (2.0 * step)
    np.testing.assert_allclose(robot.length_rates(position, rate), numeric, rtol=0, atol=1e-8)  # as above


@pytest.mark.parametrize("robot", [COGIRO, COGIRO_SWIVEL], ids=["point exits", "swivel pulleys"])
def test_structure_matrix_is_minus_the_transposed_length_jacobian_with_the_left_jacobian(robot):
    step = 1e-6
    jacobian = np.empty((robot.n_cables, 6))
    for k in range(6):
        delta = np.zeros(6)
        delta[k] = step
        jacobian[:, k] = (robot.lengths(GENERAL_POSE + delta) - robot.lengths(GENERAL_POSE - delta)) / (2.0 * step)
    matrix = robot.structure_matrix(GENERAL_POSE)
    tangent = np.eye(6)
    tangent[3:, 3:] = left_jacobian(GENERAL_POSE[3:])
    # dL/d(r, theta) = -A^T blockdiag(I, J_l); central differences as in the rate test: 1e-8
    np.testing.assert_allclose(-matrix.T @ tangent, jacobian, rtol=0, atol=1e-8)
    # without J_l the rotational columns would be wrong by far more than that (|theta| = 0.3 rad)
    assert np.max(np.abs(-matrix.T - jacobian)) > 1e-3


# ----------------------------------------------------------------------------------
# tension distribution
# ----------------------------------------------------------------------------------
def test_cogiro_data_is_caspr_s_frame_and_platform():
    span = np.ptp(cogiro.EXIT_POINTS, axis=0)
    assert 14.9 < span[0] < 15.1 and 10.9 < span[1] < 11.1
    assert np.all((cogiro.EXIT_POINTS[:, 2] > 5.38) & (cogiro.EXIT_POINTS[:, 2] < 5.43))
    assert cogiro.MASS == 91.058 and (cogiro.MIN_TENSION, cogiro.MAX_TENSION) == (100.0, 5000.0)


@pytest.mark.parametrize("robot", [COGIRO, COGIRO_SWIVEL], ids=["point exits", "swivel pulleys"])
def test_tension_distribution_balances_the_cogiro_wrench_within_the_bounds(robot):
    for pose in COGIRO_POSES:
        tensions = robot.tensions(pose)
        wrench = robot.gravity_wrench(pose)
        residual = robot.structure_matrix(pose) @ tensions + wrench
        # The balance holds by construction (f = f_p + N lambda): round-off of tensions of 1e3 N, ~1e-13 relative.
        assert np.linalg.norm(residual) <= 1e-9 * np.linalg.norm(wrench)
        assert np.all(tensions >= cogiro.MIN_TENSION) and np.all(tensions <= cogiro.MAX_TENSION)


def test_tension_distribution_is_the_minimiser_of_the_distance_to_the_mid_tensions():
    # at a pose where two cables sit at their lower bound, compare with SciPy's SLSQP on the full QP
    pose = COGIRO_POSES[2]
    matrix, wrench = COGIRO.structure_matrix(pose), COGIRO.gravity_wrench(pose)
    tensions = COGIRO.tensions(pose)
    assert np.sum(np.isclose(tensions, cogiro.MIN_TENSION, rtol=0, atol=1e-9)) >= 1  # a bound is active here
    middle = 0.5 * (cogiro.MIN_TENSION + cogiro.MAX_TENSION)
    reference = minimize(lambda f: np.sum((f - middle) ** 2) / middle**2, np.full(8, middle), method="SLSQP",
                         jac=lambda f: 2.0 * (f - middle) / middle**2,
                         bounds=[(cogiro.MIN_TENSION, cogiro.MAX_TENSION)] * 8,
                         constraints={"type": "eq", "fun": lambda f: (matrix @ f + wrench) / 1e3,
                                      "jac": lambda f: matrix / 1e3},
                         options={"ftol": 1e-14, "maxiter": 500})
    assert reference.success
    # SLSQP stops at its own tolerance: 1e-6 of the tension range (5 mN) covers it
    np.testing.assert_allclose(tensions, reference.x, rtol=0, atol=1e-6 * 4900.0)
    assert np.sum((tensions - middle) ** 2) <= np.sum((reference.x - middle) ** 2) * (1 + 1e-9)


def test_tension_distribution_is_the_closed_form_one_where_no_bound_is_active():
    pose = COGIRO_POSES[0]
    matrix, wrench = COGIRO.structure_matrix(pose), COGIRO.gravity_wrench(pose)
    middle = np.full(8, 0.5 * (cogiro.MIN_TENSION + cogiro.MAX_TENSION))
    closed_form = middle - np.linalg.pinv(matrix) @ (wrench + matrix @ middle)
    assert np.all((closed_form > cogiro.MIN_TENSION) & (closed_form < cogiro.MAX_TENSION))
    # tensions of hundreds of newtons: round-off of the SVD and the pseudo-inverse, ~1e-12 N
    np.testing.assert_allclose(COGIRO.tensions(pose), closed_form, rtol=0, atol=1e-9)


@pytest.mark.parametrize("point_mass", [False, True], ids=["8 cables, rigid", "4 cables, point mass"])
def test_symmetric_robot_at_its_centre_gets_symmetric_tensions(point_mass):
    robot = symmetric_robot(point_mass)
    centre = np.array([0.0, 0.0, 2.5]) if point_mass else np.array([0.0, 0.0, 2.5, 0.0, 0.0, 0.0])
    tensions = robot.tensions(centre)
    per_corner = tensions.reshape(4, -1)  # each row one corner, in the same cable order
    # the QP's unique minimiser inherits the mirror symmetry; round-off of tensions of ~300 N: 1e-9 relative
    np.testing.assert_allclose(per_corner, np.broadcast_to(per_corner[0], per_corner.shape), rtol=1e-9)
    weight = 91.0 * robot.gravity
    residual = robot.structure_matrix(centre) @ tensions + robot.gravity_wrench(centre)
    assert np.linalg.norm(residual) <= 1e-9 * weight


def test_point_mass_structure_matrix_is_the_force_part_of_the_rigid_one():
    rigid, point = symmetric_robot(), symmetric_robot(point_mass=True)
    position = np.array([0.5, -1.0, 2.0])
    units = point.unit_vectors(position)
    np.testing.assert_array_equal(point.structure_matrix(position), units.T)
    assert gravity_wrench(position, 91.0).shape == (3,)
    assert rigid.structure_matrix(np.r_[position, 0, 0, 0]).shape == (6, 8)


def test_pose_above_the_exits_is_outside_the_wrench_feasible_workspace():
    above = np.array([0.0, 0.0, 7.0, 0.0, 0.0, 0.0])
    with pytest.raises(UnreachableError, match=r"pose \[0\.0, 0\.0, 7\.0, 0\.0, 0\.0, 0\.0\] is outside the "
                                               r"wrench-feasible workspace"):
        COGIRO_SWIVEL.tensions(above)
    # too heavy for 5000 N cables
    heavy = IdealSpatialRobot(cogiro.EXIT_POINTS, cogiro.ANCHORS, 0.0, 1e5, 100.0, 5000.0)
    with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace"):
        heavy.tensions(cogiro.INITIAL_POSE)


def test_wrench_feasibility_along_a_trajectory_names_the_first_infeasible_pose():
    heights = np.linspace(2.0, 7.0, 51)
    poses = np.column_stack([np.zeros((51, 2)), heights, np.zeros((51, 3))])
    index, pose = COGIRO.first_infeasible_pose(poses)
    assert 0 < index < 51 and pose[2] == heights[index]
    COGIRO.tensions(poses[index - 1])  # the one before is inside
    with pytest.raises(UnreachableError, match=rf"poses\[{index}\]: pose .* outside the wrench-feasible workspace"):
        COGIRO.trajectory_tensions(poses)
    assert COGIRO.first_infeasible_pose(COGIRO_POSES) is None
    assert COGIRO.trajectory_tensions(COGIRO_POSES).shape == (len(COGIRO_POSES), 8)


def test_refusal_agrees_with_an_lp_feasibility_check_at_random_poses():
    # HiGHS (scipy.optimize.linprog) decides feasibility of A f = -w, bounds, by another method (simplex)
    rng = np.random.default_rng(5)
    verdicts = []
    for robot in (COGIRO, COGIRO_SWIVEL):
        for _ in range(100):
            pose = np.r_[rng.uniform(-7, 7), rng.uniform(-5, 5), rng.uniform(-1, 6), rng.uniform(-0.5, 0.5, 3)]
            matrix, wrench = robot.structure_matrix(pose), robot.gravity_wrench(pose)
            lp = linprog(np.zeros(8), A_eq=matrix, b_eq=-wrench, bounds=[(100.0, 5000.0)] * 8, method="highs")
            try:
                tension_distribution(matrix, wrench, 100.0, 5000.0)
                feasible = True
            except UnreachableError:
                feasible = False
            verdicts.append((feasible, lp.status == 0))
    verdicts = np.array(verdicts)
    np.testing.assert_array_equal(verdicts[:, 0], verdicts[:, 1])
    assert 0.2 < verdicts[:, 0].mean() < 0.8  # both verdicts are exercised (measured: about half feasible)


def test_workspace_boundary_is_sharp_and_never_gives_nan():
    # bisect the height where CoGiRo leaves the wrench-feasible workspace on its centre line, then step across it
    lower, upper = 2.0, 7.0
    with np.errstate(all="raise"):  # no division by zero near the boundary, where NNLS's multipliers grow
        for _ in range(60):
            middle = 0.5 * (lower + upper)
            try:
                tensions = COGIRO.tensions([0.0, 0.0, middle, 0.0, 0.0, 0.0])
                assert np.all((tensions >= 100.0) & (tensions <= 5000.0))  # never NaN
                lower = middle
            except UnreachableError:
                upper = middle
        assert upper - lower < 1e-14 and 4.6 < lower < 4.8  # measured 4.686458 m
        for exponent in range(1, 13):
            tensions = COGIRO.tensions([0.0, 0.0, lower - 10.0**-exponent, 0.0, 0.0, 0.0])
            assert np.all((tensions >= 100.0) & (tensions <= 5000.0))
            with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace"):
                COGIRO.tensions([0.0, 0.0, upper + 10.0**-exponent, 0.0, 0.0, 0.0])


# ----------------------------------------------------------------------------------
# refusals
# ----------------------------------------------------------------------------------
def test_bad_tension_bounds_are_refused_naming_the_argument():
    matrix, wrench = COGIRO.structure_matrix(cogiro.INITIAL_POSE), COGIRO.gravity_wrench(cogiro.INITIAL_POSE)
    with pytest.raises(SceneError, match="min_tension must not exceed max_tension"):
        tension_distribution(matrix, wrench, 600.0, 500.0)
    with pytest.raises(SceneError, match="min_tension must be finite and zero or positive"):
        tension_distribution(matrix, wrench, -1.0, 500.0)
    with pytest.raises(SceneError, match="max_tension"):
        tension_distribution(matrix, wrench, 100.0, np.nan)
    with pytest.raises(SceneError, match="min_tension must not exceed"):
        IdealSpatialRobot(cogiro.EXIT_POINTS, cogiro.ANCHORS, 0.0, 91.0, 5000.0, 100.0)


def test_bad_shapes_and_values_are_refused_naming_the_argument():
    matrix, wrench = COGIRO.structure_matrix(cogiro.INITIAL_POSE), COGIRO.gravity_wrench(cogiro.INITIAL_POSE)
    with pytest.raises(SceneError, match="wrench must have shape"):
        tension_distribution(matrix, wrench[:3], 100.0, 5000.0)
    with pytest.raises(SceneError, match="structure_matrix must be finite"):
        tension_distribution(np.where(matrix == matrix[0, 0], np.nan, matrix), wrench, 100.0, 5000.0)
    with pytest.raises(SceneError, match="max_tension must be a scalar or have shape"):
        tension_distribution(matrix, wrench, 100.0, [5000.0] * 7)
    with pytest.raises(SceneError, match="pose must be finite"):
        COGIRO.lengths([0.0, 0.0, np.nan, 0.0, 0.0, 0.0])
    with pytest.raises(SceneError, match="pose must have trailing shape"):
        COGIRO.lengths([0.0, 0.0, 2.0])
    with pytest.raises(SceneError, match="pose must have shape"):
        COGIRO.tensions(np.zeros((2, 6)))
    with pytest.raises(SceneError, match="anchors must have shape"):
        IdealSpatialRobot(cogiro.EXIT_POINTS, cogiro.ANCHORS[:7], 0.0, 91.0, 100.0, 5000.0)
    with pytest.raises(SceneError, match="pulley_radii must be finite and zero or positive"):
        inverse_kinematics(cogiro.INITIAL_POSE, cogiro.ANCHORS, cogiro.EXIT_POINTS, -0.1)
    with pytest.raises(SceneError, match="swivel.radius must be positive"):
        Swivel((0.0, 0.0, 5.0), -0.1)
    with pytest.raises(SceneError, match="pose_rate must have"):
        inverse_kinematics_rates(cogiro.INITIAL_POSE, np.zeros(3), cogiro.ANCHORS, cogiro.EXIT_POINTS, 0.0)
    with pytest.raises(SceneError, match="external_wrench"):
        COGIRO.tensions(cogiro.INITIAL_POSE, external_wrench=[1.0, 2.0])
