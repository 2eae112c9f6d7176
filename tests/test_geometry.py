"""Facts of the one geometry module: poses, anchors and the one pulley description."""

import numpy as np
import pytest

from cdpr_exu.statics import statics
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import (Pulley, anchor_points, left_jacobian, pulley_exit, rotation_from_vector,
                               rotation_matrix, rotation_vector)
from cdpr_exu.scenes.scene import PulleySpec, load_scene

# Geometry is closed-form: the only error is rounding, a few ulp of metre-sized lengths.
ROUNDING = 1e-12


@pytest.mark.parametrize("side", [-1, 1])
def test_a_point_exit_is_a_pulley_of_radius_zero(side):
    exit_ = Pulley((0.5, 0.2), 0.0, side)
    anchors = np.array([[0.1, -1.9], [2.0, -0.4], [-1.0, 0.6]])
    result = exit_.exit(anchors)
    offset = anchors - np.array([0.5, 0.2])
    distance = np.linalg.norm(offset, axis=1)
    assert exit_.is_point_exit
    assert result.cable_length == pytest.approx(distance, abs=ROUNDING)
    assert np.all(result.wrap_angle == 0.0)
    assert result.tangent_point == pytest.approx(np.tile([0.5, 0.2], (3, 1)), abs=ROUNDING)
    assert result.unit_vector == pytest.approx(offset / distance[:, None], abs=ROUNDING)
    assert exit_.hang_point == pytest.approx([0.5, 0.2], abs=0.0)


def test_a_point_exit_refuses_an_anchor_on_it():
    with pytest.raises(UnreachableError, match="coincides with the point exit"):
        Pulley((0.0, 0.0), 0.0).exit([0.0, 0.0])


def test_the_paid_out_length_inverts_the_winch_end():
    pulley = Pulley((-1.75, 0.0), 0.25, -1)
    for paid_out in (0.3, 2.9, 4.0):
        end = pulley.winch_end(4.0, paid_out)
        assert end[0] == pulley.hang_point[0]  # straight down the winch line
        assert pulley.paid_out_length(4.0, end) == pytest.approx(paid_out, abs=ROUNDING)


def test_the_cable_length_is_the_free_span_plus_the_arc_on_the_rim():
    # the paper's cable 1: wrap about 145.7 degrees, free length about 2.471 m (kinematics docstring)
    pulley = Pulley((-1.75, 0.0), 0.25, -1)
    exit_ = pulley.exit([-0.15, -1.9])
    assert np.degrees(exit_.wrap_angle) == pytest.approx(145.68, abs=0.01)
    assert exit_.free_length == pytest.approx(2.4713, abs=1e-4)
    assert pulley.cable_length([-0.15, -1.9]) == pytest.approx(exit_.free_length + 0.25 * exit_.wrap_angle,
                                                               abs=ROUNDING)
    # the tangent point is on the rim, and the span leaves it tangentially
    radial = exit_.tangent_point - np.array(pulley.center)
    assert np.linalg.norm(radial) == pytest.approx(0.25, abs=ROUNDING)
    assert radial @ exit_.unit_vector == pytest.approx(0.0, abs=ROUNDING)
    # the rim point and wrap of statics' angle parametrisation agree with the exit
    angle = np.arctan2(radial[1], radial[0])
    assert pulley.rim_point(angle) == pytest.approx(exit_.tangent_point, abs=ROUNDING)
    assert pulley.wrap_to(angle) == pytest.approx(exit_.wrap_angle, abs=ROUNDING)


def test_the_scene_pulley_is_a_pulley_with_contact_parameters():
    spec = PulleySpec(center=(1.75, 0.0), radius=0.25, side=1)
    assert isinstance(spec, Pulley)
    anchor = np.array([0.15, -1.9])
    assert spec.cable_length(anchor) == pytest.approx(pulley_exit((1.75, 0.0), 0.25, 1, anchor).cable_length,
                                                      abs=0.0)


def test_the_scene_decides_the_exit_once():
    scene = load_scene("paper-circle")
    assert scene.exits == tuple(scene.pulleys)
    point = scene.with_changes(cable_exit="point", winch=scene.winch.__class__(kind="fixed"))
    assert [e.radius for e in point.exits] == [0.0, 0.0]
    assert [e.center for e in point.exits] == [p.center for p in scene.pulleys]
    assert not point.pulley_contact and scene.pulley_contact


def test_statics_takes_a_point_exit_pulley_as_its_exit_point():
    cable = statics.SuspendedCable(10.0, 1e5, pulley=Pulley((0.3, 0.0), 0.0))
    assert cable.pulley is None and cable.exit_point == (0.3, 0.0)


@pytest.mark.parametrize("field, kwargs", [
    ("center", dict(center=(float("nan"), 0.0))),
    ("radius", dict(radius=-0.1)),
    ("side", dict(side=0)),
])
def test_a_bad_pulley_is_refused_naming_the_field(field, kwargs):
    with pytest.raises(SceneError, match=field):
        Pulley(**kwargs)


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
