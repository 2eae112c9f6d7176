"""Tests of cdpr_exu.statics.kinematics, planar and spatial: exits, ideal lengths, rates, structure matrix, nodes.

Behaviour both dimensions share is one test parametrised over the dimension (the paper's planar
robot over pulleys, CoGiRo over swivel pulleys of 0.1 m); what one dimension has alone (a planar
pulley's tangent and wrap, a swivel's azimuth, the initial nodes of a planar cable) has its own tests.
Pure maths, no Exudyn.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import (anchor_points, anchor_velocities, left_jacobian, planar_cross, pulley_exit,
                                    rotation_matrix, swivel_pulley_exit)
from cdpr_exu.exits import PointExit, Pulley, Swivel
from cdpr_exu.scenes.scene import CableSpec, PlatformSpec, Scene, WinchSpec, load_scene
from cdpr_exu.space import PLANE
from cdpr_exu.statics.kinematics import (cable_exits, ideal_paid_out, initial_cable_nodes, length_jacobian,
                                         pull_directions, straight_cable_nodes, structure_matrix)

# The paper's robot (paper-params.md)
PULLEY_CENTERS = np.array([[-1.75, 0.0], [1.75, 0.0]])
PULLEY_RADIUS = 0.25
SIDES = np.array([-1, 1])
ANCHORS = np.array([[-0.15, 0.1], [0.15, 0.1]])  # b_i = (-+l_p/2, h_p/2)
PAPER_POSE = np.array([0.0, -2.0, 0.0])
PAPER_ANCHOR_1 = np.array([-0.15, -1.9])

# A few reachable poses below the pulleys, rotated both ways
POSES = np.array([[0.0, -2.0, 0.0], [0.3, -1.4, 0.2], [-0.5, -2.5, -0.3], [0.1, -0.8, 0.05]])


def paper_cable_1_exit():
    return pulley_exit(PULLEY_CENTERS[0], PULLEY_RADIUS, -1, PAPER_ANCHOR_1)


def paper_robot(radius: float = PULLEY_RADIUS) -> Scene:
    """The paper's robot over pulleys of ``radius`` (0: point exits at their centres)."""
    exits = tuple(Pulley(c, radius, s) if radius > 0 else PointExit(c) for c, s in zip(PULLEY_CENTERS, SIDES))
    return Scene(exits=exits, platform=PlatformSpec(anchors=ANCHORS),
                 winch=WinchSpec(kind="kinematic" if radius > 0 else "fixed"))


def lengths(poses, radius: float = PULLEY_RADIUS):
    return ideal_paid_out(paper_robot(radius), poses)[0]


def cogiro_over_swivels(radius: float = 0.1) -> Scene:
    """The shipped CoGiRo (anchors from the centre of mass) over swivel pulleys of ``radius`` at its exit points."""
    cogiro = load_scene("spatial-cogiro")
    return replace(cogiro, exits=tuple(Swivel(e.point, radius) for e in cogiro.exits),
                   cables=tuple(replace(c, n_elements=200) for c in cogiro.cables))  # elements <= radius / 2


#: Per dimension: a robot, reachable poses, a pose rate, and ``T(pose)`` with dL/dpose = -A^T T (module notes).
ROBOTS = {
    "planar": (paper_robot(), POSES, np.array([0.3, -0.5, 0.8]), lambda pose: np.eye(3)),
    "spatial": (cogiro_over_swivels(),
                np.array([[0.0, 0.0, 2.0, 0.0, 0.0, 0.0], [1.2, -0.7, 2.3, 0.15, -0.1, 0.25],
                          [-2.0, 2.0, 2.0, -0.1, 0.05, -0.3], [2.0, -3.0, 0.5, 0.0, 0.0, 0.0]]),
                np.array([0.3, -0.2, 0.5, 0.4, -0.3, 0.6]),
                lambda pose: np.block([[np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), left_jacobian(pose[3:])]])),
}
DIMENSIONS = pytest.mark.parametrize("dimension", sorted(ROBOTS))


# ----------------------------------------------------------------------------------
# anchors and helpers
# ----------------------------------------------------------------------------------
def test_anchor_points_are_pose_position_plus_rotated_body_anchors():
    pose = np.array([0.2, -1.5, np.pi / 2])
    # a quarter turn counter-clockwise maps (-0.15, 0.1) to (-0.1, -0.15)
    expected = np.array([[0.2 - 0.1, -1.5 - 0.15], [0.2 - 0.1, -1.5 + 0.15]])
    np.testing.assert_allclose(anchor_points(pose, ANCHORS), expected, atol=1e-15)


def test_anchor_points_vectorised_over_poses_match_single_calls():
    stacked = anchor_points(POSES, ANCHORS)
    assert stacked.shape == (len(POSES), 2, 2)
    for pose, points in zip(POSES, stacked):
        np.testing.assert_array_equal(points, anchor_points(pose, ANCHORS))


def test_anchor_velocities_are_finite_difference_of_anchor_points():
    pose, rate, step = POSES[1], np.array([0.3, -0.2, 0.7]), 1e-6
    numeric = (anchor_points(pose + step * rate, ANCHORS) - anchor_points(pose - step * rate, ANCHORS)) / (2 * step)
    # central difference error ~ step^2 * |phidot|^3 * |b| ~ 1e-13; rounding ~ 1e-16 / 1e-6
    np.testing.assert_allclose(anchor_velocities(pose, rate, ANCHORS), numeric, atol=1e-9)


def test_rotation_matrix_rotates_counter_clockwise_and_cross_is_its_moment():
    np.testing.assert_allclose(rotation_matrix(np.pi / 2) @ [1.0, 0.0], [0.0, 1.0], atol=1e-15)
    # a force +z at an arm +x turns the platform counter-clockwise (positive phi)
    assert planar_cross([1.0, 0.0], [0.0, 1.0]) == 1.0


def test_hang_point_is_on_the_side_of_the_pulley():
    np.testing.assert_array_equal(Pulley((-1.75, 0.0), 0.25, -1).hang_point, [-2.0, 0.0])
    np.testing.assert_array_equal(Pulley((1.75, 0.0), 0.25, 1).hang_point, [2.0, 0.0])


# ----------------------------------------------------------------------------------
# one pulley
# ----------------------------------------------------------------------------------
def test_paper_cable_1_wraps_145_7_degrees_with_free_length_2_471():
    exit_ = paper_cable_1_exit()
    # hand computation: |p - c| = sqrt(1.6^2 + 1.9^2), wrap = 180 deg - (beta + alpha)
    distance = np.hypot(1.6, 1.9)
    wrap = np.pi - (np.arctan2(-1.9, 1.6) + np.arccos(0.25 / distance))
    assert exit_.wrap_angle == pytest.approx(wrap, abs=1e-12)
    assert np.degrees(exit_.wrap_angle) == pytest.approx(145.7, abs=0.05)  # the brief's rounded value
    assert exit_.free_length == pytest.approx(np.sqrt(distance**2 - 0.25**2), abs=1e-12)
    assert exit_.free_length == pytest.approx(2.471, abs=5e-4)
    assert exit_.arc_length == pytest.approx(0.25 * exit_.wrap_angle, abs=1e-15)
    assert exit_.cable_length == pytest.approx(3.10696, abs=1e-5)


def test_paper_cables_are_mirror_images():
    left = paper_cable_1_exit()
    right = pulley_exit(PULLEY_CENTERS[1], PULLEY_RADIUS, 1, [0.15, -1.9])
    assert right.wrap_angle == pytest.approx(left.wrap_angle, abs=1e-14)
    assert right.free_length == pytest.approx(left.free_length, abs=1e-14)
    np.testing.assert_allclose(right.tangent_point, left.tangent_point * [-1, 1], atol=1e-15)


@pytest.mark.parametrize("side", [-1, 1])
@pytest.mark.parametrize("anchor", [(-0.15, -1.9), (0.1, -2.0), (-3.0, -0.5), (-1.6, 1.0), (-1.9, -3.0)])
def test_tangent_is_on_the_rim_perpendicular_to_the_radius_and_points_at_the_anchor(side, anchor):
    center = PULLEY_CENTERS[0]
    exit_ = pulley_exit(center, PULLEY_RADIUS, side, anchor)
    radius_vector = exit_.tangent_point - center
    assert np.linalg.norm(radius_vector) == pytest.approx(PULLEY_RADIUS, abs=1e-14)
    assert np.dot(radius_vector, exit_.unit_vector) == pytest.approx(0.0, abs=1e-14)
    np.testing.assert_allclose(exit_.tangent_point + exit_.free_length * exit_.unit_vector, anchor, atol=1e-13)
    assert 0.0 <= exit_.wrap_angle < 1.5 * np.pi


def test_wrap_exceeds_180_degrees_for_an_anchor_below_on_the_inner_side():
    # s = -1 hangs on the left; an anchor right of the centre and far below is reached
    # from the bottom-right quadrant of the rim: wrap = 180 deg + a few degrees
    exit_ = pulley_exit((0.0, 0.0), 0.25, -1, (0.1, -2.0))
    expected = np.pi - (np.arctan2(-2.0, 0.1) + np.arccos(0.25 / np.hypot(0.1, 2.0)))
    assert exit_.wrap_angle > np.pi
    assert exit_.wrap_angle == pytest.approx(expected, abs=1e-12)


def test_wrap_is_zero_for_an_anchor_straight_above_the_hang_point():
    exit_ = pulley_exit((0.0, 0.0), 0.25, 1, (0.25, 2.0))
    assert exit_.wrap_angle == pytest.approx(0.0, abs=1e-12)
    assert exit_.free_length == pytest.approx(2.0, abs=1e-12)


def test_anchor_beyond_the_outer_vertical_above_the_pulley_is_unreachable():
    with pytest.raises(UnreachableError, match="without touching"):
        pulley_exit((0.0, 0.0), 0.25, 1, (0.5, 1.0))


def test_point_exit_length_is_the_distance_to_the_centre():
    exit_ = pulley_exit((1.0, 0.0), 0.0, 1, (0.0, -2.0))
    assert exit_.free_length == pytest.approx(np.sqrt(5.0), abs=1e-15)
    assert exit_.wrap_angle == 0.0
    np.testing.assert_allclose(exit_.unit_vector, np.array([-1.0, -2.0]) / np.sqrt(5.0), atol=1e-15)
    np.testing.assert_array_equal(exit_.tangent_point, [1.0, 0.0])


def test_pulley_exit_vectorised_over_anchors_matches_single_calls():
    anchors = np.array([[-0.15, -1.9], [0.3, -1.2], [-1.0, -3.0]])
    stacked = pulley_exit(PULLEY_CENTERS[0], PULLEY_RADIUS, -1, anchors)
    for i, anchor in enumerate(anchors):
        single = pulley_exit(PULLEY_CENTERS[0], PULLEY_RADIUS, -1, anchor)
        assert stacked.wrap_angle[i] == single.wrap_angle
        assert stacked.free_length[i] == single.free_length
        np.testing.assert_array_equal(stacked.tangent_point[i], single.tangent_point)


@pytest.mark.parametrize("radius", [0.25, 0.0])
@pytest.mark.parametrize("anchor", [(-0.15, -1.9), (0.1, -2.0), (-1.9, -3.0)])
def test_length_rate_is_u_dot_v_by_finite_differences(radius, anchor):
    center, side = PULLEY_CENTERS[0], -1
    velocity, step = np.array([0.4, 0.7]), 1e-6
    anchor = np.asarray(anchor)
    numeric = (
        pulley_exit(center, radius, side, anchor + step * velocity).cable_length
        - pulley_exit(center, radius, side, anchor - step * velocity).cable_length
    ) / (2 * step)
    # central difference: truncation ~ step^2 * curvature ~ 1e-12, rounding ~ 1e-16 / step = 1e-10
    assert pulley_exit(center, radius, side, anchor).unit_vector @ velocity == pytest.approx(numeric, abs=1e-8)


@pytest.mark.parametrize(
    "args, name",
    [
        (((0.0, 0.0), -0.1, -1, (0.0, -1.0)), "radius"),
        (((0.0, 0.0), 0.25, 0, (0.0, -1.0)), "side"),
        (((0.0, 0.0), 0.25, "left", (0.0, -1.0)), "side"),
        (((0.0, np.nan), 0.25, 1, (0.0, -1.0)), "center"),
        (((0.0, 0.0), 0.25, 1, (0.0, -1.0, 2.0)), "anchor"),
        (((0.0, 0.0), np.inf, 1, (0.0, -1.0)), "radius"),
    ],
)
def test_bad_pulley_arguments_raise_scene_error_naming_them(args, name):
    with pytest.raises(SceneError, match=name):
        pulley_exit(*args)


# ----------------------------------------------------------------------------------
# the whole robot, through its exits: both dimensions
# ----------------------------------------------------------------------------------
@DIMENSIONS
def test_lengths_and_structure_matrices_vectorised_over_poses_match_single_calls(dimension):
    robot, poses, _, _ = ROBOTS[dimension]
    stacked, matrices = ideal_paid_out(robot, poses)[0], structure_matrix(robot, poses)
    assert stacked.shape == (len(poses), robot.n_cables)
    assert matrices.shape == (len(poses), robot.space.wrench_size, robot.n_cables)
    for pose, single, matrix in zip(poses, stacked, matrices):
        np.testing.assert_array_equal(single, ideal_paid_out(robot, pose)[0])
        np.testing.assert_array_equal(matrix, structure_matrix(robot, pose))


def _central_differences(robot, pose, directions, step=1e-6):
    """dL/d(pose) along each direction (rows of ``directions``) by central differences, shape (m, k)."""
    return np.column_stack([(ideal_paid_out(robot, pose + step * e)[0] - ideal_paid_out(robot, pose - step * e)[0])
                            / (2 * step) for e in np.atleast_2d(directions)])


@DIMENSIONS
def test_length_rates_are_central_differences_of_the_lengths(dimension):
    robot, poses, rate, _ = ROBOTS[dimension]
    for pose in poses:
        # truncation ~ step^2 times the third derivative ~ 1e-12, rounding ~ 1e-16 * 10 m / step = 1e-9 m/s
        np.testing.assert_allclose(ideal_paid_out(robot, pose, rate)[1], _central_differences(robot, pose, rate)[:, 0],
                                   rtol=0, atol=1e-8)


@DIMENSIONS
def test_structure_matrix_is_minus_the_transposed_length_jacobian(dimension):
    """dL/dpose = -A^T T(pose): T = I in the plane, blockdiag(I, J_l(theta)) in space (the rotation vector's rate
    is not the angular velocity)."""
    robot, poses, rate, tangent = ROBOTS[dimension]
    for pose in poses:
        matrix = structure_matrix(robot, pose)
        numeric = _central_differences(robot, pose, np.eye(robot.space.pose_size))
        np.testing.assert_allclose(-matrix.T @ tangent(pose), numeric, rtol=0, atol=1e-8)  # as the rate test
        # the same formula as the rates (u . v), up to rounding
        np.testing.assert_allclose(-matrix.T @ tangent(pose) @ rate, ideal_paid_out(robot, pose, rate)[1], atol=1e-13)


def test_without_the_left_jacobian_the_spatial_rotation_columns_are_wrong():
    robot, poses, _, _ = ROBOTS["spatial"]
    pose = poses[1]  # |theta| = 0.3 rad
    assert np.max(np.abs(-structure_matrix(robot, pose).T - _central_differences(robot, pose, np.eye(6)))) > 1e-3


@DIMENSIONS
def test_length_jacobian_position_columns_are_the_exits_unit_vectors_and_pulls_their_opposite(dimension):
    robot, poses, _, _ = ROBOTS[dimension]
    units = np.stack([e.unit_vector for e in cable_exits(robot, poses)], axis=-2)
    d = robot.space.position_size
    np.testing.assert_array_equal(length_jacobian(robot, poses)[..., :d], units)  # sign flips are exact
    np.testing.assert_array_equal(pull_directions(robot, poses), -units)
    np.testing.assert_allclose(np.linalg.norm(units, axis=-1), 1.0, rtol=0, atol=1e-15)


def planar_point_mass(**changes) -> Scene:
    """Four cables from the corners of a 3.5 x 4 m frame to a planar point mass (zero anchors), 2.5 kg."""
    exits = (PointExit((-1.75, 0.0)), PointExit((1.75, 0.0)), PointExit((-1.75, -4.0)), PointExit((1.75, -4.0)))
    return Scene(cables=(CableSpec(),) * 4, exits=exits, platform=PlatformSpec(anchors=((0.0, 0.0),) * 4),
                 winch=WinchSpec(kind="fixed"), **changes)


def spatial_point_mass() -> Scene:
    """Four of CoGiRo's cables, one per corner, on a 91 kg point mass."""
    cogiro, keep = load_scene("spatial-cogiro"), [0, 2, 4, 6]
    return replace(cogiro, cables=tuple(cogiro.cables[i] for i in keep), exits=tuple(cogiro.exits[i] for i in keep),
                   platform=PlatformSpec(mass=91.0, anchors=((0.0, 0.0, 0.0),) * 4))


@pytest.mark.parametrize("robot, pose", [(planar_point_mass, (0.3, -1.5, 0.0)),
                                         (spatial_point_mass, (0.5, -1.0, 2.0, 0.0, 0.0, 0.0))],
                         ids=["planar", "spatial"])
def test_a_point_mass_structure_matrix_is_the_force_part_the_pulls(robot, pose):
    robot, pose = robot(), np.asarray(pose)
    matrix = structure_matrix(robot, pose)
    assert matrix.shape == (robot.space.position_size, 4)
    np.testing.assert_array_equal(matrix, pull_directions(robot, pose).T)


def test_a_planar_robot_written_in_space_has_the_same_lengths_rates_and_structure_matrix():
    """The paper's robot in the x-z plane of space (Space.embed: (x, z, phi) -> (x, 0, z, 0, -phi, 0)): each
    pulley a swivel pulley whose inlet is the pulley's hang point, each anchor (b_x, 0, b_z). The swivel's
    disc turns into the plane (azimuth 0 or pi), where it is the planar pulley."""
    planar = paper_robot()
    inlets = [(Pulley(c, PULLEY_RADIUS, s).hang_point[0], 0.0, 0.0) for c, s in zip(PULLEY_CENTERS, SIDES)]
    spatial = Scene(dimension=3, cables=(CableSpec(n_elements=30),) * 2,
                    exits=tuple(Swivel(inlet, PULLEY_RADIUS) for inlet in inlets),
                    platform=PlatformSpec(anchors=tuple((b[0], 0.0, b[1]) for b in ANCHORS), inertia=(0.01,) * 3))
    rates = np.array([[0.3, -0.5, 0.8], [-0.2, 0.1, -0.4], [0.0, 0.7, 0.2], [0.5, 0.5, 0.0]])
    poses_3d, rates_3d = PLANE.embed(POSES), PLANE.embed(rates)
    # Round-off: lengths of about 2 m through Rodrigues' formula and the swivel's plane, a few 1e-16 relative
    planar_lengths, planar_rates = ideal_paid_out(planar, POSES, rates)
    spatial_lengths, spatial_rates = ideal_paid_out(spatial, poses_3d, rates_3d)
    np.testing.assert_allclose(spatial_lengths, planar_lengths, rtol=0, atol=1e-12)
    np.testing.assert_allclose(spatial_rates, planar_rates, rtol=0, atol=1e-12)
    # rows (f_x, f_y, f_z, m_x, m_y, m_z) against (f_x, f_z, m): m_y = -m (the planar turn is about -y)
    matrix, planar_matrix = structure_matrix(spatial, poses_3d), structure_matrix(planar, POSES)
    np.testing.assert_allclose(matrix[:, [0, 2, 4]] * np.array([1, 1, -1])[:, None], planar_matrix, rtol=0, atol=1e-12)
    np.testing.assert_allclose(matrix[:, [1, 3, 5]], 0.0, rtol=0, atol=1e-12)  # nothing out of the plane


# ----------------------------------------------------------------------------------
# the planar robot
# ----------------------------------------------------------------------------------
def test_inverse_kinematics_of_the_paper_pose_is_symmetric():
    assert lengths(PAPER_POSE) == pytest.approx([paper_cable_1_exit().cable_length] * 2, abs=1e-14)


def test_point_exit_inverse_kinematics_are_the_distances():
    distances = np.linalg.norm(anchor_points(POSES, ANCHORS) - PULLEY_CENTERS, axis=-1)
    np.testing.assert_allclose(lengths(POSES, radius=0.0), distances, atol=1e-15)


def test_planar_structure_matrix_matches_a_hand_computation():
    # point exits 5 m from the anchors along (0.6, 0.8) and (-0.8, 0.6), the platform turned a quarter turn:
    # R(90 deg) b_1 = (-0.1, -0.15), R(90 deg) b_2 = (-0.1, 0.15)
    # moments: (-0.1)(0.8) - (-0.15)(0.6) = 0.01; (-0.1)(0.6) - (0.15)(-0.8) = 0.06
    pose = np.array([0.0, -2.0, np.pi / 2])
    robot = Scene(cables=(CableSpec(unstrained_length=5.0),) * 2,
                  exits=(PointExit((2.9, 1.85)), PointExit((-4.1, 1.15))),
                  platform=PlatformSpec(anchors=ANCHORS, initial_pose=tuple(pose)), winch=WinchSpec(kind="fixed"))
    expected = np.array([[0.6, -0.8], [0.8, 0.6], [0.01, 0.06]])
    np.testing.assert_allclose(structure_matrix(robot, pose), expected, atol=1e-15)


def test_paper_platform_at_rest_hangs_on_equal_upward_tensions():
    matrix = structure_matrix(paper_robot(), PAPER_POSE)
    weight = np.array([0.0, -2.5 * 9.8, 0.0])
    tensions = np.linalg.lstsq(matrix, -weight, rcond=None)[0]
    assert np.all(tensions > 0.0)
    assert tensions[0] == pytest.approx(tensions[1], rel=1e-12)
    np.testing.assert_allclose(matrix @ tensions + weight, 0.0, atol=1e-12)


def test_anchor_inside_the_pulley_is_unreachable():
    with pytest.raises(UnreachableError, match="inside the pulley"):
        pulley_exit((0.0, 0.0), 0.25, -1, (0.1, 0.1))
    with pytest.raises(UnreachableError):
        lengths([-1.6, 0.0, 0.0])


def test_bad_robot_arguments_raise_scene_error_naming_them():
    with pytest.raises(SceneError, match="pose"):
        lengths([0.0, -2.0])
    with pytest.raises(SceneError, match="pose"):
        structure_matrix(ROBOTS["spatial"][0], [0.0, 0.0, 2.0])


# ----------------------------------------------------------------------------------
# the swivel pulley (spatial)
# ----------------------------------------------------------------------------------
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
# initial cable nodes
# ----------------------------------------------------------------------------------
def paper_cable_1_nodes():
    return initial_cable_nodes(PULLEY_CENTERS[0], PULLEY_RADIUS, -1, PAPER_ANCHOR_1, 0.25, 15)


def test_paper_initial_nodes_have_equal_chords_and_end_at_the_anchor():
    nodes = paper_cable_1_nodes()
    assert nodes.shape == (16, 2)
    # roots are solved to ~1e-14 on a 1-Lipschitz function
    np.testing.assert_allclose(np.linalg.norm(np.diff(nodes, axis=0), axis=1), 0.25, atol=1e-9)
    np.testing.assert_array_equal(nodes[-1], PAPER_ANCHOR_1)


def test_paper_initial_nodes_stay_out_of_the_pulley_and_some_lie_on_its_rim():
    distances = np.linalg.norm(paper_cable_1_nodes() - PULLEY_CENTERS[0], axis=1)
    assert np.all(distances >= PULLEY_RADIUS - 1e-9)  # rim nodes are at r_p up to rounding
    assert np.sum(np.abs(distances - PULLEY_RADIUS) < 1e-12) >= 2  # the arc carries nodes


def test_paper_initial_node_0_hangs_below_the_hang_point_on_the_vertical_line():
    node_0 = paper_cable_1_nodes()[0]
    assert node_0[0] == pytest.approx(-2.0, abs=1e-12)
    assert node_0[1] < 0.0
    # 3.75 m of chords minus the ideal length 3.107 m, lengthened by the chord deficit on the arc
    assert node_0[1] == pytest.approx(-0.6678, abs=1e-4)


def test_initial_nodes_lie_on_the_ideal_path_in_order_from_the_winch():
    nodes = paper_cable_1_nodes()
    exit_ = paper_cable_1_exit()
    on_vertical = np.abs(nodes[:, 0] + 2.0) < 1e-12
    on_rim = np.abs(np.linalg.norm(nodes - PULLEY_CENTERS[0], axis=1) - PULLEY_RADIUS) < 1e-12
    offset = nodes - exit_.tangent_point
    on_segment = np.abs(planar_cross(offset, exit_.unit_vector)) < 1e-12
    assert np.all(on_vertical | on_rim | on_segment)
    # from the winch: vertical nodes first (z rising to the hang point), then the rim, then the segment
    first_off_vertical = np.argmin(on_vertical)
    assert np.all(on_vertical[:first_off_vertical]) and np.all(np.diff(nodes[:first_off_vertical, 1]) > 0)


def test_initial_nodes_of_a_point_exit_are_straight_to_the_centre_then_down():
    # a 3-4-5 triangle: the anchor is 0.5 m from the centre, two 0.25 m elements reach it
    nodes = initial_cable_nodes((0.0, 0.0), 0.0, 1, (0.4, -0.3), 0.25, 4)
    expected = [[0.0, -0.5], [0.0, -0.25], [0.0, 0.0], [0.2, -0.15], [0.4, -0.3]]
    np.testing.assert_allclose(nodes, expected, atol=1e-12)  # root finder tolerance ~1e-14


def test_initial_nodes_single_straight_segment_when_the_cable_is_short():
    nodes = initial_cable_nodes(PULLEY_CENTERS[0], PULLEY_RADIUS, -1, PAPER_ANCHOR_1, 0.5, 2)
    exit_ = paper_cable_1_exit()
    np.testing.assert_allclose(nodes[0], PAPER_ANCHOR_1 - 1.0 * exit_.unit_vector, atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"element_length": 0.0}, "element_length"),
        ({"element_length": np.nan}, "element_length"),
        ({"n_elements": 0}, "n_elements"),
        ({"n_elements": 2.5}, "n_elements"),
        ({"side": 3}, "side"),
    ],
)
def test_bad_initial_node_arguments_raise_scene_error_naming_them(kwargs, name):
    arguments = {
        "center": PULLEY_CENTERS[0],
        "radius": PULLEY_RADIUS,
        "side": -1,
        "anchor": PAPER_ANCHOR_1,
        "element_length": 0.25,
        "n_elements": 15,
    }
    arguments.update(kwargs)
    with pytest.raises(SceneError, match=name):
        initial_cable_nodes(**arguments)


def test_initial_nodes_for_an_anchor_inside_the_pulley_are_unreachable():
    with pytest.raises(UnreachableError):
        initial_cable_nodes((0.0, 0.0), 0.25, -1, (0.0, -0.2), 0.1, 4)


def test_straight_cable_nodes_are_evenly_spaced_from_start_to_end():
    nodes = straight_cable_nodes((-1.75, 0.0), (0.0, -1.75), 15)
    assert nodes.shape == (16, 2)
    np.testing.assert_array_equal(nodes[0], [-1.75, 0.0])
    np.testing.assert_allclose(nodes[-1], [0.0, -1.75], atol=1e-15)
    np.testing.assert_allclose(np.diff(nodes, axis=0), np.full((15, 2), [1.75 / 15, -1.75 / 15]), atol=1e-15)
    with pytest.raises(SceneError, match="n_elements"):
        straight_cable_nodes((0.0, 0.0), (1.0, 0.0), 0)
