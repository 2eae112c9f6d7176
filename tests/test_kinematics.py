"""Tests of cdpr_exu.statics.kinematics: pulley tangents, ideal lengths, rates, wrench matrix, nodes."""

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.exits import PointExit, Pulley
from cdpr_exu.scenes.scene import PlatformSpec, Scene, WinchSpec
from cdpr_exu.statics.kinematics import (
    anchor_points,
    anchor_velocities,
    cable_exits,
    ideal_paid_out,
    initial_cable_nodes,
    planar_cross,
    pulley_exit,
    rotation_matrix,
    straight_cable_nodes,
    structure_matrix,
)

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


def pulls(poses, radius: float = PULLEY_RADIUS):
    """Unit vectors from each anchor towards its exit, (m, 2) or (N, m, 2): the directions of pull."""
    return -np.stack([e.unit_vector for e in cable_exits(paper_robot(radius), poses)], axis=-2)


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


def test_anchor_inside_the_pulley_is_unreachable():
    with pytest.raises(UnreachableError, match="inside the pulley"):
        pulley_exit((0.0, 0.0), 0.25, -1, (0.1, 0.1))
    with pytest.raises(UnreachableError):
        lengths([-1.6, 0.0, 0.0])


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
# the whole robot, through its exits
# ----------------------------------------------------------------------------------
def test_inverse_kinematics_of_the_paper_pose_is_symmetric():
    assert lengths(PAPER_POSE) == pytest.approx([paper_cable_1_exit().cable_length] * 2, abs=1e-14)


def test_inverse_kinematics_vectorised_over_poses_matches_single_calls():
    stacked = lengths(POSES)
    assert stacked.shape == (len(POSES), 2)
    for pose, single in zip(POSES, stacked):
        np.testing.assert_array_equal(single, lengths(pose))


def test_point_exit_inverse_kinematics_are_the_distances():
    distances = np.linalg.norm(anchor_points(POSES, ANCHORS) - PULLEY_CENTERS, axis=-1)
    np.testing.assert_allclose(lengths(POSES, radius=0.0), distances, atol=1e-15)


def test_inverse_kinematics_rates_are_finite_difference_of_lengths():
    rate, step, robot = np.array([0.3, -0.5, 0.8]), 1e-6, paper_robot()
    for pose in POSES:
        analytic = ideal_paid_out(robot, pose, rate)[1]
        # truncation ~ step^2, rounding ~ 1e-16 / step = 1e-10
        np.testing.assert_allclose(analytic, (lengths(pose + step * rate) - lengths(pose - step * rate)) / (2 * step),
                                   atol=1e-8)


def test_structure_matrix_matches_a_hand_computation():
    pose = np.array([0.0, -2.0, np.pi / 2])
    units = np.array([[0.6, 0.8], [-0.8, 0.6]])
    # R(90 deg) b_1 = (-0.1, -0.15), R(90 deg) b_2 = (-0.1, 0.15)
    # moments: (-0.1)(0.8) - (-0.15)(0.6) = 0.01; (-0.1)(0.6) - (0.15)(-0.8) = 0.06
    expected = np.array([[0.6, -0.8], [0.8, 0.6], [0.01, 0.06]])
    np.testing.assert_allclose(structure_matrix(pose, ANCHORS, units), expected, atol=1e-15)


def test_structure_matrix_transpose_maps_twist_to_minus_length_rates():
    rate = np.array([0.3, -0.5, 0.8])
    for pose in POSES:
        matrix = structure_matrix(pose, ANCHORS, pulls(pose))
        rates = ideal_paid_out(paper_robot(), pose, rate)[1]
        np.testing.assert_allclose(-matrix.T @ rate, rates, atol=1e-14)  # same formula, rounding only


def test_paper_platform_at_rest_hangs_on_equal_upward_tensions():
    matrix = structure_matrix(PAPER_POSE, ANCHORS, pulls(PAPER_POSE))
    weight = np.array([0.0, -2.5 * 9.8, 0.0])
    tensions = np.linalg.lstsq(matrix, -weight, rcond=None)[0]
    assert np.all(tensions > 0.0)
    assert tensions[0] == pytest.approx(tensions[1], rel=1e-12)
    np.testing.assert_allclose(matrix @ tensions + weight, 0.0, atol=1e-12)


def test_structure_matrix_vectorised_over_poses():
    units = pulls(POSES)
    stacked = structure_matrix(POSES, ANCHORS, units)
    assert stacked.shape == (len(POSES), 3, 2)
    np.testing.assert_array_equal(stacked[1], structure_matrix(POSES[1], ANCHORS, units[1]))


def test_bad_robot_arguments_raise_scene_error_naming_them():
    with pytest.raises(SceneError, match="pose"):
        lengths([0.0, -2.0])
    with pytest.raises(SceneError, match="unit_vectors"):
        structure_matrix(PAPER_POSE, ANCHORS, np.ones((3, 2)))


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
