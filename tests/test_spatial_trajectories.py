"""Tests of cdpr_exu.scenes.spatial_trajectories: horizontal circles, holds, quintic moves, dicts, planar agreement."""

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import left_jacobian, rotation_from_vector, rotation_matrix, rotation_vector
from cdpr_exu.scenes.spatial_trajectories import (
    SpatialCircleTrajectory,
    SpatialHoldTrajectory,
    SpatialPointToPointTrajectory,
    spatial_trajectory_from_dict,
)
from cdpr_exu.scenes.trajectories import CircleTrajectory, PointToPointTrajectory

RAMPED_TILTED_CIRCLE = SpatialCircleTrajectory(center=(0.1, -0.2, 1.5), radius=0.3, angular_rate=-0.7,
                                               rotation=(0.05, 0.0, 0.2), tilt=(0.04, -0.03, 0.0), ramp_time=2.0)
MOVE = SpatialPointToPointTrajectory(start=(0.0, 0.1, 1.0, 0.0, 0.1, 0.0), end=(0.3, -0.2, 1.4, 0.1, -0.1, 0.3),
                                     duration=1.5, start_time=0.5)
TRAJECTORIES = [
    SpatialCircleTrajectory(center=(0.0, 0.0, 2.0)),
    RAMPED_TILTED_CIRCLE,
    SpatialHoldTrajectory((0.1, -0.1, 2.0, 0.05, 0.0, -0.02)),
    MOVE,
]
IDS = ["circle", "circle_ramp_tilt", "hold", "point_to_point"]
TIMES = np.linspace(-0.5, 6.0, 53)
# The quintic blends have a jerk jump at their ends (0.5, 2.0); keep finite differences
# off those points, where a central difference errs by O(step) rather than O(step^2).
SMOOTH_TIMES = TIMES + 0.0123


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=IDS)
def test_scalar_time_gives_a_pose_of_six_and_array_time_gives_rows(trajectory):
    for method in (trajectory.pose, trajectory.velocity, trajectory.acceleration):
        assert method(1.0).shape == (6,)
        rows = method(TIMES)
        assert rows.shape == (len(TIMES), 6)
        np.testing.assert_allclose(rows[7], method(TIMES[7]), atol=1e-15)


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=IDS)
def test_velocity_and_acceleration_are_central_differences_of_pose_and_velocity(trajectory):
    step = 1e-5
    t = SMOOTH_TIMES
    numeric_velocity = (trajectory.pose(t + step) - trajectory.pose(t - step)) / (2 * step)
    numeric_acceleration = (trajectory.velocity(t + step) - trajectory.velocity(t - step)) / (2 * step)
    # central differences: truncation ~ step^2 / 6 * |third derivative| (< 10 here) ~ 2e-10,
    # rounding ~ 1e-16 * |pose| (< 3) / step ~ 3e-11; 1e-7 leaves a wide margin
    np.testing.assert_allclose(trajectory.velocity(t), numeric_velocity, atol=1e-7)
    np.testing.assert_allclose(trajectory.acceleration(t), numeric_acceleration, atol=1e-7)


def test_circle_position_stays_at_the_radius_from_the_centre_at_the_centres_height():
    circle = RAMPED_TILTED_CIRCLE
    pose = circle.pose(np.linspace(-1.0, 12.0, 131))  # before, during and after the ramp
    offset = pose[:, :2] - np.array(circle.center[:2])
    np.testing.assert_allclose(np.hypot(offset[:, 0], offset[:, 1]), circle.radius, atol=1e-15)
    np.testing.assert_array_equal(pose[:, 2], circle.center[2])  # horizontal: z never changes
    np.testing.assert_array_equal(circle.velocity(TIMES)[:, 2], 0.0)


def test_circle_starts_below_the_centre_in_y_and_rocks_once_per_turn():
    circle = SpatialCircleTrajectory(center=(0.0, 0.0, 2.0), radius=0.4, angular_rate=1.5,
                                     rotation=(0.0, 0.0, 0.1), tilt=(0.05, 0.0, 0.0))
    np.testing.assert_allclose(circle.pose(0.0), [0.0, -0.4, 2.0, 0.0, 0.0, 0.1], atol=1e-15)
    quarter = 0.5 * np.pi / 1.5
    np.testing.assert_allclose(circle.pose(quarter), [0.4, 0.0, 2.0, 0.05, 0.0, 0.1], atol=1e-15)
    period = 4 * quarter
    np.testing.assert_allclose(circle.pose(period), circle.pose(0.0), atol=1e-15)


def test_ramped_circle_starts_from_rest_and_reaches_the_angular_rate_after_the_ramp():
    circle = RAMPED_TILTED_CIRCLE
    np.testing.assert_allclose(circle.pose(0.0)[:3], [0.1, -0.5, 1.5], atol=1e-15)
    np.testing.assert_allclose(circle.pose(0.0)[3:], circle.rotation, atol=1e-15)
    # all six components, including the tilt's rotation-vector rate, start at rest
    np.testing.assert_allclose(circle.velocity(0.0), 0.0, atol=1e-15)
    np.testing.assert_allclose(circle.acceleration(0.0), 0.0, atol=1e-15)
    _, rate, rate_change = circle.phase(np.array([2.0, 3.0, 7.5]))
    np.testing.assert_allclose(rate, -0.7, atol=1e-15)
    np.testing.assert_allclose(rate_change, 0.0, atol=1e-15)
    speed = np.linalg.norm(circle.velocity(np.linspace(2.0, 8.0, 13))[:, :3], axis=1)
    np.testing.assert_allclose(speed, 0.3 * 0.7, atol=1e-15)
    # after the ramp: the unramped circle delayed by half the ramp time
    steady = SpatialCircleTrajectory(center=circle.center, radius=0.3, angular_rate=-0.7,
                                     rotation=circle.rotation, tilt=circle.tilt)
    t = np.linspace(2.0, 8.0, 13)
    for method in ("pose", "velocity", "acceleration"):
        np.testing.assert_allclose(getattr(circle, method)(t), getattr(steady, method)(t - 1.0), atol=1e-14)


def test_circle_phase_is_the_planar_circles_phase():
    # the ramp is the planar CircleTrajectory's, built from the same imported quintic helpers
    t = np.linspace(-1.0, 5.0, 61)
    planar = CircleTrajectory(angular_rate=-0.7, ramp_time=2.0)
    for spatial, flat in zip(RAMPED_TILTED_CIRCLE.phase(t), planar.phase(t)):
        np.testing.assert_array_equal(spatial, flat)


@pytest.mark.parametrize("circle", [
    RAMPED_TILTED_CIRCLE,
    SpatialCircleTrajectory(center=(0.0, 0.0, 2.0), rotation=(0.0, 0.0, 1.2), tilt=(0.3, 0.0, 0.0)),
], ids=["small_tilt", "large_turn"])
def test_velocity_is_the_rotation_vector_rate_not_the_angular_velocity(circle):
    t, step = 3.3, 1e-5
    # fixed-frame angular velocity from the rotation matrices: R(t+h) R(t-h)^T = exp(2h [omega]x) + O(h^3)
    change = rotation_from_vector(circle.pose(t + step)[3:]) @ rotation_from_vector(circle.pose(t - step)[3:]).T
    omega = rotation_vector(change) / (2 * step)
    theta, theta_rate = circle.pose(t)[3:], circle.velocity(t)[3:]
    np.testing.assert_allclose(omega, left_jacobian(theta) @ theta_rate, atol=1e-8)  # O(h^2) + 1e-16 / h
    # base rotation and tilt are not parallel: omega - theta' ~ (1 - cos a) / a^2 theta x theta' (a = |theta|,
    # the factor 1/2 for small a, 0.44 at a = 1.2) plus a smaller [theta]x^2 term
    expected_gap = 0.5 * np.linalg.norm(np.cross(theta, theta_rate))
    assert np.linalg.norm(omega - theta_rate) > 0.5 * expected_gap > 0.0


def test_point_to_point_is_rest_to_rest_and_holds_outside_the_motion():
    start, end = np.array(MOVE.start), np.array(MOVE.end)
    np.testing.assert_array_equal(MOVE.pose(0.0), start)
    np.testing.assert_allclose(MOVE.pose(2.0), end, atol=1e-15)
    np.testing.assert_allclose(MOVE.pose(9.0), end, atol=1e-15)
    np.testing.assert_allclose(MOVE.pose(1.25), 0.5 * (start + end), atol=1e-15)  # symmetric quintic
    for t in (0.5, 2.0):
        np.testing.assert_allclose(MOVE.velocity(t), 0.0, atol=1e-15)
        np.testing.assert_allclose(MOVE.acceleration(t), 0.0, atol=1e-12)


def test_planar_rotation_phi_is_the_spatial_rotation_about_minus_y():
    for phi in (0.3, -1.1, 2.5):
        spatial = rotation_from_vector((0.0, -phi, 0.0))
        np.testing.assert_allclose(spatial[np.ix_([0, 2], [0, 2])], rotation_matrix(phi), atol=1e-15)
        np.testing.assert_allclose(spatial[1], [0.0, 1.0, 0.0], atol=1e-15)  # y stays y


def test_point_to_point_in_the_x_z_plane_is_the_planar_move_with_theta_y_equal_to_minus_phi():
    planar = PointToPointTrajectory(start=(0.1, -2.0, 0.2), end=(0.3, -1.5, -0.4), duration=1.5, start_time=0.5)

    def lift(pose):
        x, z, phi = pose
        return (x, 0.0, z, 0.0, -phi, 0.0)

    spatial = SpatialPointToPointTrajectory(start=lift(planar.start), end=lift(planar.end), duration=1.5,
                                            start_time=0.5)
    sign = np.array([1.0, 1.0, -1.0])
    for method in ("pose", "velocity", "acceleration"):
        rows = getattr(spatial, method)(TIMES)
        np.testing.assert_allclose(rows[:, [0, 2, 4]], getattr(planar, method)(TIMES) * sign, atol=1e-15)
        np.testing.assert_array_equal(rows[:, [1, 3, 5]], 0.0)
    # and the platform anchors agree: planar r + R(phi) b, spatial r + exp([theta]x) (b_x, 0, b_z)
    anchor = np.array([0.2, 0.05])
    for flat, pose in zip(planar.pose(TIMES), spatial.pose(TIMES)):
        planar_point = flat[:2] + rotation_matrix(float(flat[2])) @ anchor
        spatial_point = pose[:3] + rotation_from_vector(pose[3:]) @ np.array([anchor[0], 0.0, anchor[1]])
        np.testing.assert_allclose(spatial_point[[0, 2]], planar_point, atol=1e-15)
        assert abs(spatial_point[1]) < 1e-15


def test_hold_is_constant_and_still():
    hold = SpatialHoldTrajectory((0.1, -0.1, 2.0, 0.05, 0.0, -0.02))
    np.testing.assert_array_equal(hold.pose(TIMES), np.tile([0.1, -0.1, 2.0, 0.05, 0.0, -0.02], (len(TIMES), 1)))
    np.testing.assert_array_equal(hold.velocity(TIMES), 0.0)
    np.testing.assert_array_equal(hold.acceleration(3.0), np.zeros(6))


def test_circle_turning_times_are_the_quarter_turns_where_x_or_y_is_extreme():
    circle = SpatialCircleTrajectory(center=(0.0, 0.0, 2.0), tilt=(0.0, 0.05, 0.0))
    times = circle.turning_times(5.0)
    np.testing.assert_allclose(np.diff(times), 0.5 * np.pi / 1.5, atol=1e-15)
    velocity = circle.velocity(times)
    np.testing.assert_allclose(np.min(np.abs(velocity[:, :2]), axis=1), 0.0, atol=1e-15)
    assert RAMPED_TILTED_CIRCLE.turning_times(5.0).size == 0  # ramped: no closed form
    rocking_in_place = SpatialCircleTrajectory(center=(0.0, 0.0, 2.0), radius=0.0, tilt=(0.05, 0.0, 0.0))
    assert rocking_in_place.turning_times(5.0).size > 0
    np.testing.assert_array_equal(MOVE.turning_times(5.0), [0.5, 2.0])


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=IDS)
def test_dict_round_trip_gives_an_equal_trajectory(trajectory):
    data = trajectory.to_dict()
    assert all(not isinstance(value, tuple) for value in data.values())  # TOML-friendly lists
    assert spatial_trajectory_from_dict(data) == trajectory


def test_dicts_use_kind_and_field_names():
    assert spatial_trajectory_from_dict({"kind": "circle", "center": [0, 0, 2]}) == \
        SpatialCircleTrajectory(center=(0.0, 0.0, 2.0))
    hold = SpatialHoldTrajectory((0.0, 0.0, 1.0, 0.0, 0.0, 0.0))
    assert spatial_trajectory_from_dict({"kind": "hold", "pose": [0, 0, 1, 0, 0, 0]}) == hold
    assert hold.to_dict() == {"kind": "hold", "pose": [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]}
    move = spatial_trajectory_from_dict({"kind": "point_to_point", "start": [0, 0, 1, 0, 0, 0],
                                         "end": [0, 0, 2, 0, 0, 0], "duration": 2})
    assert move.duration == 2.0 and move.end == (0.0, 0.0, 2.0, 0.0, 0.0, 0.0)


GOOD_POSE = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize(
    "data, name",
    [
        ({"kind": "spiral", "center": [0, 0, 2]}, "kind"),
        ({"center": [0, 0, 2]}, "kind"),
        ({"kind": "circle", "center": [0, 0, 2], "speed": 1.0}, "speed"),
        ({"kind": "circle", "center": [0, 0, 2], "radius": np.nan}, "trajectory.radius"),
        ({"kind": "circle", "center": [0, 0, 2], "radius": -0.4}, "trajectory.radius"),
        ({"kind": "circle", "center": [0, 0, 2], "ramp_time": -1.0}, "trajectory.ramp_time"),
        ({"kind": "circle", "center": [0, 0, 2], "angular_rate": np.inf}, "trajectory.angular_rate"),
        ({"kind": "circle", "center": [0.0, -1.6]}, "trajectory.center"),  # a planar centre
        ({"kind": "circle", "center": [0, 0, 2], "tilt": [0.1, 0.0]}, "trajectory.tilt"),
        ({"kind": "circle", "center": [0, 0, 2], "rotation": [0.0, "up", 0.0]}, r"trajectory.rotation\[1\]"),
        ({"kind": "circle", "radius": 0.4}, "trajectory.center"),
        ({"kind": "hold"}, "trajectory.pose"),
        ({"kind": "hold", "pose": [0.0, -2.0, 0.0]}, "trajectory.pose"),  # a planar pose
        ({"kind": "hold", "held_pose": GOOD_POSE}, "held_pose"),
        ({"kind": "point_to_point", "end": GOOD_POSE}, "trajectory.start"),
        ({"kind": "point_to_point", "start": GOOD_POSE}, "trajectory.end"),
        ({"kind": "point_to_point", "start": GOOD_POSE, "end": GOOD_POSE, "duration": 0.0}, "trajectory.duration"),
        ({"kind": "point_to_point", "start": GOOD_POSE, "end": [0, 0, np.inf, 0, 0, 0]}, r"trajectory.end\[2\]"),
    ],
)
def test_bad_trajectory_fields_raise_scene_error_naming_them(data, name):
    with pytest.raises(SceneError, match=name):
        spatial_trajectory_from_dict(data)


def test_a_non_table_is_refused():
    with pytest.raises(SceneError, match="trajectory must be a table"):
        spatial_trajectory_from_dict([("kind", "hold")])


def test_trajectories_are_frozen():
    with pytest.raises(AttributeError):
        RAMPED_TILTED_CIRCLE.radius = 1.0
