"""Tests of cdpr_exu.scenes.trajectories: the paper's circle, holds, quintic moves, dict round-trips."""

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.trajectories import (
    CircleTrajectory,
    HoldTrajectory,
    PointToPointTrajectory,
    trajectory_from_dict,
)

TRAJECTORIES = [
    CircleTrajectory(),
    CircleTrajectory(center=(0.1, -1.5), radius=0.3, angular_rate=-0.7, rotation=0.1, ramp_time=2.0),
    HoldTrajectory((0.1, -2.0, 0.05)),
    PointToPointTrajectory(start=(0.0, -2.0, 0.0), end=(0.3, -1.5, 0.2), duration=1.5, start_time=0.5),
]
TIMES = np.linspace(-0.5, 6.0, 53)
# The quintic blends have a jerk jump at their ends (0.5, 2.0); keep finite differences
# off those points, where a central difference errs by O(step) rather than O(step^2).
SMOOTH_TIMES = TIMES + 0.0123


def test_default_circle_is_the_papers_reference():
    t = np.linspace(0.0, 10.0, 41)
    expected = np.stack([0.4 * np.sin(1.5 * t), -1.6 - 0.4 * np.cos(1.5 * t), 0.0 * t], axis=-1)
    np.testing.assert_allclose(CircleTrajectory().pose(t), expected, atol=1e-15)
    np.testing.assert_allclose(CircleTrajectory().pose(0.0), [0.0, -2.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=lambda tr: tr.kind)
def test_scalar_time_gives_a_pose_and_array_time_gives_rows(trajectory):
    for method in (trajectory.pose, trajectory.velocity, trajectory.acceleration):
        assert method(1.0).shape == (3,)
        rows = method(TIMES)
        assert rows.shape == (len(TIMES), 3)
        np.testing.assert_allclose(rows[7], method(TIMES[7]), atol=1e-15)


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=lambda tr: tr.kind)
def test_velocity_and_acceleration_are_finite_differences(trajectory):
    step = 1e-5
    t = SMOOTH_TIMES
    numeric_velocity = (trajectory.pose(t + step) - trajectory.pose(t - step)) / (2 * step)
    numeric_acceleration = (trajectory.velocity(t + step) - trajectory.velocity(t - step)) / (2 * step)
    # central differences: truncation ~ step^2 * |third derivative| (< 100) ~ 1e-8,
    # rounding ~ 1e-16 / step ~ 1e-11
    np.testing.assert_allclose(trajectory.velocity(t), numeric_velocity, atol=1e-7)
    np.testing.assert_allclose(trajectory.acceleration(t), numeric_acceleration, atol=1e-7)


def test_ramped_circle_starts_from_rest_and_reaches_the_steady_rate():
    circle = CircleTrajectory(ramp_time=2.0)
    np.testing.assert_allclose(circle.pose(0.0), [0.0, -2.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(circle.velocity(0.0), 0.0, atol=1e-15)
    np.testing.assert_allclose(circle.acceleration(0.0), 0.0, atol=1e-15)
    # after the ramp: the paper's circle delayed by half the ramp time
    t = np.linspace(2.0, 8.0, 13)
    np.testing.assert_allclose(circle.pose(t), CircleTrajectory().pose(t - 1.0), atol=1e-14)
    np.testing.assert_allclose(circle.velocity(t), CircleTrajectory().velocity(t - 1.0), atol=1e-14)


def test_ramped_circle_acceleration_is_continuous_at_the_end_of_the_ramp():
    circle = CircleTrajectory(ramp_time=2.0)
    before, after = circle.acceleration(2.0 - 1e-9), circle.acceleration(2.0 + 1e-9)
    np.testing.assert_allclose(before, after, atol=1e-7)  # jerk is bounded, so ~1e-9 jumps


def test_point_to_point_is_rest_to_rest_and_holds_outside_the_motion():
    move = PointToPointTrajectory(start=(0.0, -2.0, 0.0), end=(0.3, -1.5, 0.2), duration=1.5, start_time=0.5)
    np.testing.assert_array_equal(move.pose(0.0), [0.0, -2.0, 0.0])
    np.testing.assert_allclose(move.pose(2.0), [0.3, -1.5, 0.2], atol=1e-15)
    np.testing.assert_allclose(move.pose(9.0), [0.3, -1.5, 0.2], atol=1e-15)
    np.testing.assert_allclose(move.pose(1.25), [0.15, -1.75, 0.1], atol=1e-15)  # symmetric quintic
    for t in (0.5, 2.0):
        np.testing.assert_allclose(move.velocity(t), 0.0, atol=1e-15)
        np.testing.assert_allclose(move.acceleration(t), 0.0, atol=1e-12)


def test_hold_is_constant_and_still():
    hold = HoldTrajectory((0.1, -2.0, 0.05))
    np.testing.assert_array_equal(hold.pose(TIMES), np.tile([0.1, -2.0, 0.05], (len(TIMES), 1)))
    np.testing.assert_array_equal(hold.velocity(TIMES), 0.0)
    np.testing.assert_array_equal(hold.acceleration(3.0), [0.0, 0.0, 0.0])


@pytest.mark.parametrize("trajectory", TRAJECTORIES, ids=lambda tr: tr.kind)
def test_dict_round_trip_gives_an_equal_trajectory(trajectory):
    data = trajectory.to_dict()
    assert all(not isinstance(value, tuple) for value in data.values())  # TOML-friendly lists
    assert trajectory_from_dict(data) == trajectory


def test_dicts_use_kind_and_field_names():
    assert trajectory_from_dict({"kind": "circle"}) == CircleTrajectory()
    assert trajectory_from_dict({"kind": "hold", "pose": [0.0, -1.0, 0.0]}) == HoldTrajectory((0.0, -1.0, 0.0))
    assert HoldTrajectory((0.0, -1.0, 0.0)).to_dict() == {"kind": "hold", "pose": [0.0, -1.0, 0.0]}
    move = trajectory_from_dict({"kind": "point_to_point", "start": [0, -2, 0], "end": [0, -1, 0], "duration": 2})
    assert move.duration == 2.0 and move.end == (0.0, -1.0, 0.0)


@pytest.mark.parametrize(
    "data, name",
    [
        ({"kind": "spiral"}, "kind"),
        ({"radius": 0.4}, "kind"),
        ({"kind": "circle", "speed": 1.0}, "speed"),
        ({"kind": "circle", "radius": -0.4}, "radius"),
        ({"kind": "circle", "angular_rate": np.nan}, "angular_rate"),
        ({"kind": "circle", "center": [0.0]}, "center"),
        ({"kind": "circle", "ramp_time": -1.0}, "ramp_time"),
        ({"kind": "hold", "pose": [0.0, "low", 0.0]}, "pose"),
        ({"kind": "point_to_point", "duration": 0.0}, "duration"),
        ({"kind": "point_to_point", "end": [0.0, np.inf, 0.0]}, "end"),
    ],
)
def test_bad_trajectory_fields_raise_scene_error_naming_them(data, name):
    with pytest.raises(SceneError, match=name):
        trajectory_from_dict(data)


def test_trajectories_are_frozen():
    with pytest.raises(AttributeError):
        CircleTrajectory().radius = 1.0
