"""The Space (cdpr_exu.space): the one decision on the dimension, and its planar and spatial kernels."""

import pickle

import numpy as np
import pytest

from cdpr_exu.core import geometry
from cdpr_exu.core.errors import SceneError
from cdpr_exu.space import PLANE, SPACE, space_of

POSES = np.array([[0.0, -2.0, 0.0], [0.3, -1.4, 0.2], [-0.5, -2.5, -0.3]])
ANCHORS = np.array([[-0.15, 0.1], [0.15, 0.1]])


def test_space_of_is_the_one_decision_and_refuses_other_dimensions():
    assert space_of(2) is PLANE and space_of(3) is SPACE
    for bad in (1, 4, True, "3", None):
        with pytest.raises(SceneError, match="dimension must be 2 \\(planar\\) or 3 \\(spatial\\)"):
            space_of(bad)


def test_each_space_knows_its_sizes_and_labels():
    assert (PLANE.pose_size, PLANE.position_size, PLANE.rotation_size, PLANE.vertical, PLANE.wrench_size) == (3, 2, 1, 1, 3)
    assert (SPACE.pose_size, SPACE.position_size, SPACE.rotation_size, SPACE.vertical, SPACE.wrench_size) == (6, 3, 3, 2, 6)
    assert PLANE.pose_labels == ("x", "z", "rotation") and SPACE.pose_labels == ("x", "y", "z", "rx", "ry", "rz")
    assert PLANE.pose_units == ("m", "m", "rad")


def test_a_space_stays_one_object_through_a_pickle():
    assert pickle.loads(pickle.dumps(PLANE)) is PLANE and pickle.loads(pickle.dumps(SPACE)) is SPACE


def test_the_planar_anchors_are_the_planar_kernels_bit_for_bit():
    assert np.array_equal(PLANE.anchor_points(POSES, ANCHORS), geometry.anchor_points(POSES, ANCHORS))
    rates = np.array([[0.1, -0.2, 0.5]] * 3)
    assert np.array_equal(PLANE.anchor_velocities(POSES, rates, ANCHORS),
                          geometry.anchor_velocities(POSES, rates, ANCHORS))


def test_the_embedded_planar_robot_has_its_anchors_where_the_spatial_kernels_put_them():
    spatial_anchors = np.column_stack([ANCHORS[:, 0], np.zeros(2), ANCHORS[:, 1]])
    planar = PLANE.anchor_points(POSES, ANCHORS)
    spatial = SPACE.anchor_points(PLANE.embed(POSES), spatial_anchors)
    # the same rotation through Rodrigues' formula and through cos/sin: round-off apart
    np.testing.assert_allclose(spatial[..., [0, 2]], planar, rtol=0, atol=1e-15)
    assert np.all(spatial[..., 1] == 0.0)
    rates = np.array([[0.1, -0.2, 0.5]] * 3)
    velocities = SPACE.anchor_velocities(PLANE.embed(POSES), PLANE.embed(rates), spatial_anchors)
    np.testing.assert_allclose(velocities[..., [0, 2]], PLANE.anchor_velocities(POSES, rates, ANCHORS),
                               rtol=0, atol=1e-15)
    assert np.array_equal(SPACE.embed(PLANE.embed(POSES)), PLANE.embed(POSES))


def test_the_rotation_matrices_agree_through_the_embedding():
    for phi in (0.0, 0.4, -1.3):
        spatial = SPACE.rotation_matrix(PLANE.embed(np.array([0.0, 0.0, phi]))[3:])
        np.testing.assert_allclose(spatial[np.ix_([0, 2], [0, 2])], PLANE.rotation_matrix(phi), rtol=0, atol=1e-15)


def test_the_rotation_error_is_the_angle_between_the_orientations_in_both_spaces():
    reference = np.zeros((3, 3))
    assert PLANE.rotation_error_deg(POSES, reference) == pytest.approx(np.degrees(np.abs(POSES[:, 2])), abs=0)
    assert SPACE.rotation_error_deg(PLANE.embed(POSES), PLANE.embed(reference)) == pytest.approx(
        np.degrees(np.abs(POSES[:, 2])), abs=1e-12)


def test_the_inertia_is_a_moment_in_the_plane_and_three_principal_moments_in_space():
    assert PLANE.inertia("platform.inertia", 0.02, rigid=True) == 0.02
    assert SPACE.inertia("platform.inertia", [1, 2, 3], rigid=True) == (1.0, 2.0, 3.0)
    assert SPACE.inertia("platform.inertia", [0, 0, 0], rigid=False) == (0.0, 0.0, 0.0)
    for space, value, words in ((PLANE, 0.0, "platform.inertia"), (PLANE, [1, 2, 3], "platform.inertia"),
                                (SPACE, 0.5, "platform.inertia must be a finite 3-vector"),
                                (SPACE, [1.0, -1.0, 1.0], "platform.inertia must be zero or positive")):
        with pytest.raises(SceneError, match=words):
            space.inertia("platform.inertia", value, rigid=False)
    with pytest.raises(SceneError, match="platform.inertia must be positive"):
        SPACE.inertia("platform.inertia", [1.0, 0.0, 1.0], rigid=True)
    assert PLANE.is_rigid(point_mass=True) and SPACE.is_rigid(point_mass=False) and not SPACE.is_rigid(point_mass=True)


def test_the_rotation_rate_inverts_the_angular_velocity_in_both_spaces():
    """``rotation_rate`` is ``angular_velocity``'s inverse (identity in the plane, J_l^-1 in space), and in
    space it is the rotation vector's time derivative: a central difference of theta(t) agrees with it."""
    rng = np.random.default_rng(3)
    for space, size in ((PLANE, 1), (SPACE, 3)):
        theta, rate = rng.normal(size=(5, size)), rng.normal(size=(5, size))
        omega = space.angular_velocity(theta, rate)
        np.testing.assert_allclose(space.rotation_rate(theta, omega), rate, rtol=1e-12, atol=1e-12)
    # a rotation turning at a constant body-fixed angular velocity: theta(t) = log(R0 exp(t w_body))
    r0 = geometry.rotation_from_vector([0.3, -0.5, 0.8])
    w_body, t, h = np.array([0.4, 1.1, -0.7]), 0.37, 1e-5
    theta = [geometry.rotation_vector(r0 @ geometry.rotation_from_vector(s * w_body)) for s in (t - h, t, t + h)]
    omega_fixed = r0 @ geometry.rotation_from_vector(t * w_body) @ w_body
    # the central difference is exact to O(h^2) ~ 1e-10 rad/s here
    np.testing.assert_allclose(SPACE.rotation_rate(theta[1], omega_fixed), (theta[2] - theta[0]) / (2 * h), atol=1e-8)
