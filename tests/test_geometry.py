"""Facts of the one geometry module: poses, anchors, rotations and the exits' kernels (the exits: test_exits.py)."""

import numpy as np
import pytest

from cdpr_exu.core.geometry import anchor_points, left_jacobian, rotation_from_vector, rotation_matrix, rotation_vector

# Geometry is closed-form: the only error is rounding, a few ulp of metre-sized lengths.
ROUNDING = 1e-12


def test_one_angle_and_an_array_of_angles_give_the_same_rotation():
    angles = np.array([-2.0, -0.3, 0.0, 0.7, 3.0])
    stacked = rotation_matrix(angles)
    for angle, matrix in zip(angles, stacked):
        single = rotation_matrix(float(angle))
        assert single == pytest.approx(matrix, abs=1e-15)
        assert single @ single.T == pytest.approx(np.eye(2), abs=1e-15)
    pose = np.array([0.1, -1.8, 0.4])
    assert anchor_points(pose, [[0.2, 0.0]])[0] == pytest.approx(pose[:2] + rotation_matrix(0.4) @ [0.2, 0.0],
                                                                 abs=1e-15)


@pytest.mark.parametrize("theta", [[0.0, 0.0, 0.0], [1e-9, -2e-9, 3e-9], [0.3, -0.2, 0.5], [0.0, 3.0, 0.1]])
def test_rotation_vector_and_matrix_are_inverse_and_left_jacobian_is_their_derivative(theta):
    theta = np.array(theta)
    rotation = rotation_from_vector(theta)
    # orthonormal and inverse of each other to round-off (angles of order 1)
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-14)
    np.testing.assert_allclose(rotation_vector(rotation), theta, atol=1e-12)
    h = 1e-7
    for e in np.eye(3):
        # exp([theta + h e]) R^T = exp([J_l h e]) to first order: central differences, error O(h^2)
        change = (rotation_from_vector(theta + h * e) - rotation_from_vector(theta - h * e)) / (2 * h) @ rotation.T
        axial = 0.5 * np.array([change[2, 1] - change[1, 2], change[0, 2] - change[2, 0], change[1, 0] - change[0, 1]])
        np.testing.assert_allclose(axial, left_jacobian(theta) @ e, atol=1e-8)


def test_a_platform_is_a_point_mass_only_when_every_anchor_is_exactly_at_its_centre():
    """One rule for the scene, the catenary statics and the chain statics (they used three: exact zeros,
    ``not any`` and ``np.allclose``, which took anchors 1e-9 m off the centre for a point mass)."""
    from cdpr_exu.core.geometry import all_at_centre

    assert all_at_centre([[0.0, 0.0, 0.0], [-0.0, 0.0, 0.0]]) and all_at_centre(np.zeros((4, 2)))
    assert not all_at_centre([[0.0, 0.0, 0.0], [0.0, 1e-9, 0.0]])
