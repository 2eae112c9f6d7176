"""Tests of the exact-angle bending spring-damper (cdpr_exu.physics.bending)."""

import numpy as np
import pytest

from cdpr_exu.physics.bending import (
    BendingSpringDamper,
    bending_angles,
    bending_energy,
    cable_joints,
    curvature_stiffness_matrix,
)
from cdpr_exu.core.errors import SceneError


def bending_force(positions, velocities, joints, stiffness, damping):
    """The force of ``BendingSpringDamper`` (a copy of its buffer) for the given joints."""
    springs = BendingSpringDamper(np.size(positions) // 2, joints, stiffness, damping)
    return springs.force(positions, velocities).copy()


def bending_jacobian(positions, velocities, joints, stiffness, damping):
    springs = BendingSpringDamper(np.size(positions) // 2, joints, stiffness, damping)
    return tuple(m.copy() for m in springs.jacobian(positions, velocities))


def bent_cable(n_nodes=6, element_length=0.1, turn_per_joint=0.5, seed=0):
    """Positions (2N,) of a chain turning by turn_per_joint [rad] at each joint, plus noise."""
    rng = np.random.default_rng(seed)
    heading = np.cumsum(np.full(n_nodes - 1, turn_per_joint)) + rng.normal(0.0, 0.1, n_nodes - 1)
    lengths = element_length * (1.0 + 0.2 * rng.uniform(-1.0, 1.0, n_nodes - 1))
    steps = lengths[:, None] * np.stack([np.cos(heading), np.sin(heading)], axis=1)
    origin = np.array([0.3, -0.2])
    points = np.vstack([origin, origin + np.cumsum(steps, axis=0)])
    return points.ravel()


def random_parameters(n_joints, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.5, 2.0, n_joints), rng.uniform(0.01, 0.1, n_joints)


def rotation(angle):
    return np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])


def central_difference(function, x, step):
    columns = []
    for i in range(x.size):
        dx = np.zeros_like(x)
        dx[i] = step
        columns.append((function(x + dx) - function(x - dx)) / (2.0 * step))
    return np.stack(columns, axis=-1)


def test_force_is_minus_gradient_of_energy():
    positions = bent_cable(turn_per_joint=0.9)
    joints = cable_joints([6])
    stiffness, _ = random_parameters(len(joints))
    force = bending_force(positions, np.zeros_like(positions), joints, stiffness, 0.0)
    gradient = central_difference(lambda q: np.array(bending_energy(q, joints, stiffness)), positions, 1e-6)
    # step 1e-6 m on 0.1 m elements: truncation ~1e-12, round-off ~1e-16/1e-6 relative to |V|
    np.testing.assert_allclose(force, -gradient, rtol=0, atol=1e-7 * np.abs(force).max())


@pytest.mark.parametrize("turn_per_joint", [0.3, 1.0, 2.0, 3.0])
def test_jacobians_match_central_differences_of_force(turn_per_joint):
    positions = bent_cable(turn_per_joint=turn_per_joint)
    velocities = np.random.default_rng(2).normal(0.0, 1.0, positions.size)
    joints = cable_joints([6])
    stiffness, damping = random_parameters(len(joints))
    stiffness_matrix, damping_matrix = bending_jacobian(positions, velocities, joints, stiffness, damping)
    numeric_k = -central_difference(
        lambda q: bending_force(q, velocities, joints, stiffness, damping), positions, 1e-6)
    numeric_d = -central_difference(
        lambda v: bending_force(positions, v, joints, stiffness, damping), velocities, 1e-6)
    # relative 1e-6 of the largest entry: central-difference truncation ~ (step/l)^2 ~ 1e-10
    np.testing.assert_allclose(stiffness_matrix, numeric_k, rtol=0, atol=1e-6 * np.abs(numeric_k).max())
    # the force is linear in v: central differences are exact up to round-off
    np.testing.assert_allclose(damping_matrix, numeric_d, rtol=0, atol=1e-6 * np.abs(numeric_d).max())


def test_stiffness_matrix_is_not_symmetric_with_damping_and_bending_velocity():
    positions = bent_cable(turn_per_joint=0.7)
    velocities = np.random.default_rng(3).normal(0.0, 1.0, positions.size)
    joints = cable_joints([6])
    stiffness_matrix, _ = bending_jacobian(positions, velocities, joints, 1.0, 0.5)
    undamped, _ = bending_jacobian(positions, velocities, joints, 1.0, 0.0)
    assert np.abs(stiffness_matrix - stiffness_matrix.T).max() > 1e-3 * np.abs(stiffness_matrix).max()
    # without damping K is the Hessian of the energy: symmetric to round-off
    np.testing.assert_allclose(undamped, undamped.T, rtol=0, atol=1e-12 * np.abs(undamped).max())


def test_combined_call_equals_separate_calls():
    positions = bent_cable(turn_per_joint=1.2)
    velocities = np.random.default_rng(4).normal(0.0, 1.0, positions.size)
    joints = cable_joints([6])
    stiffness, damping = random_parameters(len(joints))
    force = bending_force(positions, velocities, joints, stiffness, damping)
    stiffness_matrix, damping_matrix = bending_jacobian(positions, velocities, joints, stiffness, damping)
    combined = BendingSpringDamper(6, joints, stiffness, damping).force_and_jacobian(positions, velocities)
    # same arithmetic, different summation order at most: round-off only
    np.testing.assert_allclose(combined[0], force, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(combined[1], stiffness_matrix, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(combined[2], damping_matrix, rtol=1e-13, atol=1e-12)


def test_straight_cable_has_zero_force_and_energy():
    positions = np.column_stack([np.linspace(0.0, 1.0, 8), 0.5 * np.linspace(0.0, 1.0, 8)]).ravel()
    joints = cable_joints([8])
    assert bending_energy(positions, joints, 3.0) == 0.0
    # collinear points: cross product is round-off, ~1e-16 rad times k / l
    np.testing.assert_allclose(bending_force(positions, np.zeros_like(positions), joints, 3.0, 0.2), 0.0, atol=1e-12)


def test_rigid_motion_keeps_angles_and_rotates_force():
    positions = bent_cable(turn_per_joint=1.1)
    velocities = np.random.default_rng(5).normal(0.0, 1.0, positions.size)
    joints = cable_joints([6])
    stiffness, damping = random_parameters(len(joints))
    turn = rotation(2.3)
    moved = (positions.reshape(-1, 2) @ turn.T + [4.0, -7.0]).ravel()
    moved_velocities = (velocities.reshape(-1, 2) @ turn.T).ravel()
    # angles are invariant to round-off of coordinates of size ~10 m
    np.testing.assert_allclose(bending_angles(moved, joints), bending_angles(positions, joints), atol=1e-12)
    force = bending_force(positions, velocities, joints, stiffness, damping)
    moved_force = bending_force(moved, moved_velocities, joints, stiffness, damping)
    np.testing.assert_allclose(moved_force, (force.reshape(-1, 2) @ turn.T).ravel(),
                               atol=1e-10 * np.abs(force).max())


def test_internal_forces_have_zero_resultant_and_zero_moment():
    positions = bent_cable(turn_per_joint=1.5)
    velocities = np.random.default_rng(6).normal(0.0, 1.0, positions.size)
    joints = cable_joints([6])
    stiffness, damping = random_parameters(len(joints))
    force = bending_force(positions, velocities, joints, stiffness, damping).reshape(-1, 2)
    points = positions.reshape(-1, 2)
    scale = np.abs(force).max()
    # exact cancellation in exact arithmetic: round-off only
    np.testing.assert_allclose(force.sum(axis=0), 0.0, atol=1e-12 * scale)
    moment = np.sum(points[:, 0] * force[:, 1] - points[:, 1] * force[:, 0])
    assert abs(moment) < 1e-12 * scale * np.abs(points).max() * len(points)


@pytest.mark.parametrize("angle", [0.2, -0.4, np.pi / 3, 2.0, -2.5, np.pi - 1e-3, -(np.pi - 1e-3)])
def test_single_joint_bent_by_angle_gives_moment_k_times_angle(angle):
    first_length, second_length, stiffness = 0.15, 0.25, 4.0
    middle = np.array([first_length, 0.0])
    end = middle + second_length * np.array([np.cos(angle), np.sin(angle)])
    positions = np.concatenate([[0.0, 0.0], middle, end])
    joints = np.array([[0, 1, 2]])
    # the angle is exact up to round-off, also beyond 90 degrees and near 180
    assert bending_angles(positions, joints)[0] == pytest.approx(angle, abs=1e-14)
    force = bending_force(positions, np.zeros(6), joints, stiffness, 0.0).reshape(3, 2)
    element = end - middle
    # moment of the end force about the middle node is the restoring moment -k angle
    moment = element[0] * force[2, 1] - element[1] * force[2, 0]
    assert moment == pytest.approx(-stiffness * angle, rel=1e-12)
    # the end force is perpendicular to its element, magnitude k |angle| / |e|
    assert np.dot(force[2], element) == pytest.approx(0.0, abs=1e-12)
    assert np.linalg.norm(force[2]) * second_length == pytest.approx(stiffness * abs(angle), rel=1e-12)
    # same for the first node and the first element
    moment_first = -first_length * force[0, 1]  # lever from node 1 to node 0 is (-l1, 0)
    assert moment_first == pytest.approx(stiffness * angle, rel=1e-12)
    assert bending_energy(positions, joints, stiffness) == pytest.approx(0.5 * stiffness * angle**2, rel=1e-12)


def test_two_cables_in_one_call_equal_sum_of_separate_calls():
    first = bent_cable(n_nodes=5, turn_per_joint=0.8, seed=7)
    second = bent_cable(n_nodes=7, turn_per_joint=-1.3, seed=8)
    positions = np.concatenate([first, second])
    rng = np.random.default_rng(9)
    velocities = rng.normal(0.0, 1.0, positions.size)
    joints = cable_joints([5, 7])
    stiffness, damping = random_parameters(len(joints))
    force = bending_force(positions, velocities, joints, stiffness, damping)
    stiffness_matrix, damping_matrix = bending_jacobian(positions, velocities, joints, stiffness, damping)
    expected_force = np.zeros_like(force)
    expected_k = np.zeros_like(stiffness_matrix)
    expected_d = np.zeros_like(damping_matrix)
    for rows in (slice(0, 3), slice(3, 8)):
        # one cable at a time over the global node list: it only touches its own coordinates
        expected_force += bending_force(positions, velocities, joints[rows], stiffness[rows], damping[rows])
        k, d = bending_jacobian(positions, velocities, joints[rows], stiffness[rows], damping[rows])
        expected_k += k
        expected_d += d
    np.testing.assert_allclose(force, expected_force, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(stiffness_matrix, expected_k, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(damping_matrix, expected_d, rtol=1e-13, atol=1e-12)
    assert np.all(stiffness_matrix[:10, 10:] == 0.0) and np.all(stiffness_matrix[10:, :10] == 0.0)


def test_joints_may_be_arbitrary_triplets():
    positions = bent_cable(n_nodes=5, turn_per_joint=0.6)
    joints = np.array([[4, 2, 0], [1, 3, 2]])
    velocities = np.random.default_rng(10).normal(0.0, 1.0, positions.size)
    stiffness_matrix, _ = bending_jacobian(positions, velocities, joints, 1.0, 0.2)
    numeric = -central_difference(lambda q: bending_force(q, velocities, joints, 1.0, 0.2), positions, 1e-6)
    # same tolerance as the consecutive-triplet Jacobian test
    np.testing.assert_allclose(stiffness_matrix, numeric, rtol=0, atol=1e-6 * np.abs(numeric).max())


def test_curvature_spring_matches_exact_angle_energy_at_small_angles():
    element_length, stiffness = 0.2, 3.0
    joints = cable_joints([6])
    # an evenly spaced chain with small turns of 1e-3 rad
    heading = np.cumsum(np.full(5, 1e-3))
    points = np.vstack([[0, 0], np.cumsum(element_length * np.column_stack([np.cos(heading), np.sin(heading)]), axis=0)])
    positions = points.ravel()
    matrix = curvature_stiffness_matrix(6, joints, stiffness, element_length)
    linear_energy = 0.5 * positions @ matrix @ positions
    # |p_a - 2 p_b + p_c| = 2 l sin(dtheta / 2): relative difference ~ dtheta^2 / 12 ~ 1e-7
    assert linear_energy == pytest.approx(bending_energy(positions, joints, stiffness), rel=1e-6)
    np.testing.assert_allclose(matrix, matrix.T)
    assert np.linalg.eigvalsh(matrix).min() > -1e-9 * np.abs(matrix).max()


def test_invalid_arguments_raise_scene_error_naming_the_field():
    positions = bent_cable(n_nodes=4)
    with pytest.raises(SceneError, match="joints"):
        bending_force(positions, np.zeros(8), [[0, 1, 4]], 1.0, 0.0)
    with pytest.raises(SceneError, match="velocities"):
        bending_force(positions, np.zeros(6), [[0, 1, 2]], 1.0, 0.0)
    with pytest.raises(SceneError, match="positions"):
        bending_force(positions.reshape(-1, 2), np.zeros(8), [[0, 1, 2]], 1.0, 0.0)
    with pytest.raises(SceneError, match="zero length"):
        bending_force(positions, np.zeros(8), [[0, 0, 2]], 1.0, 0.0)
    with pytest.raises(SceneError, match="element_length"):
        curvature_stiffness_matrix(4, [[0, 1, 2]], 1.0, 0.0)


def test_spring_damper_refuses_bad_coordinates_and_parameters():
    positions = bent_cable(n_nodes=5, seed=12)
    springs = BendingSpringDamper(5, cable_joints([5]), 1.0, 0.1)
    assert springs.energy(positions) == bending_energy(positions, cable_joints([5]), 1.0)
    with pytest.raises(SceneError, match="positions"):
        springs.force(positions[:-2], np.zeros(10))
    with pytest.raises(SceneError, match="damping"):
        BendingSpringDamper(5, cable_joints([5]), 1.0, np.ones(2))
