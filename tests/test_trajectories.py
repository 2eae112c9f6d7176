"""Tests of cdpr_exu.scenes.trajectories: one set of kinds for the plane and for space.

What both spaces share is one test parametrised over the space (shapes, derivatives against
finite differences, the ramp from rest, rest-to-rest moves, holds, dict round trips, field
checks); what is a fact of one space is its own test (the paper's vertical circle, the
horizontal spatial circle, the rotation vector's rate against the angular velocity). A toy kind
registered at test time loads in a planar and a spatial scene. Waypoints and trajectory files:
the spline's facts, the refusals through ``cdpr run``, and a planar and a spatial robot that
follow such a path on the real solver.
"""

import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
import tomli_w

from cdpr_exu.cli import main
from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import left_jacobian, rotation_from_vector, rotation_matrix, rotation_vector
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import load_scene, save_scene, scene_from_dict
from cdpr_exu.scenes.trajectories import (
    TRAJECTORY_KINDS,
    CircleTrajectory,
    HoldTrajectory,
    PointToPointTrajectory,
    Trajectory,
    WaypointsTrajectory,
    trajectory_from_dict,
)
from cdpr_exu.space import PLANE, SPACE
from cdpr_exu.statics.kinematics import ideal_paid_out
from cdpr_exu.statics.workspace import reference_samples

PAPER_CIRCLE = CircleTrajectory((0.0, -1.6))
RAMPED_TILTED_CIRCLE = CircleTrajectory((0.1, -0.2, 1.5), radius=0.3, angular_rate=-0.7, rotation=(0.05, 0.0, 0.2),
                                        tilt=(0.04, -0.03, 0.0), ramp_time=2.0, space=SPACE)
SPATIAL_MOVE = PointToPointTrajectory((0.0, 0.1, 1.0, 0.0, 0.1, 0.0), (0.3, -0.2, 1.4, 0.1, -0.1, 0.3), duration=1.5,
                                      start_time=0.5, space=SPACE)
PLANAR_MOVE = PointToPointTrajectory((0.0, -2.0, 0.0), (0.3, -1.5, 0.2), duration=1.5, start_time=0.5)
PLANAR_WAYPOINTS = WaypointsTrajectory((0.5, 1.5, 2.5, 4.5), ((0.0, -2.0, 0.0), (0.2, -1.8, 0.1), (0.3, -1.9, -0.05),
                                                            (0.1, -2.0, 0.0)))
SPATIAL_WAYPOINTS = WaypointsTrajectory((0.5, 2.0, 4.5), ((0.0, 0.1, 1.0, 0.0, 0.1, 0.0), (0.3, -0.2, 1.4, 0.1, -0.1, 0.3),
                                                       (0.2, 0.0, 1.2, 0.0, 0.0, 0.1)), space=SPACE)
TRAJECTORIES = {
    "planar_circle": PAPER_CIRCLE,
    "planar_circle_ramp_rotation": CircleTrajectory((0.1, -1.5), radius=0.3, angular_rate=-0.7, rotation=0.1,
                                                    ramp_time=2.0),
    "planar_circle_rocking": CircleTrajectory((0.1, -1.5), radius=0.3, rotation=0.1, tilt=0.05),
    "planar_hold": HoldTrajectory((0.1, -2.0, 0.05)),
    "planar_point_to_point": PLANAR_MOVE,
    "planar_waypoints": PLANAR_WAYPOINTS,
    "spatial_circle": CircleTrajectory((0.0, 0.0, 2.0), space=SPACE),
    "spatial_circle_ramp_tilt": RAMPED_TILTED_CIRCLE,
    "spatial_hold": HoldTrajectory((0.1, -0.1, 2.0, 0.05, 0.0, -0.02), space=SPACE),
    "spatial_point_to_point": SPATIAL_MOVE,
    "spatial_waypoints": SPATIAL_WAYPOINTS,
}
SPACES = pytest.mark.parametrize("space", [PLANE, SPACE], ids=["planar", "spatial"])
ALL = pytest.mark.parametrize("trajectory", list(TRAJECTORIES.values()), ids=list(TRAJECTORIES))
TIMES = np.linspace(-0.5, 6.0, 53)
# The quintic blends have a jerk jump at their ends (0.5, 2.0); keep finite differences
# off those points, where a central difference errs by O(step) rather than O(step^2).
SMOOTH_TIMES = TIMES + 0.0123


def _ramped_circle(space):
    """A ramped circle of ``space`` (rocking in space) and the same circle without its ramp."""
    circle = PAPER_CIRCLE if space is PLANE else RAMPED_TILTED_CIRCLE
    circle = replace(circle, angular_rate=-0.7, ramp_time=2.0)
    return circle, replace(circle, ramp_time=0.0)


# ------------------------------------------------------------------ shared by both spaces


@ALL
def test_scalar_time_gives_a_pose_and_array_time_gives_rows(trajectory):
    size = trajectory.space.pose_size
    for method in (trajectory.pose, trajectory.velocity, trajectory.acceleration):
        assert method(1.0).shape == (size,)
        rows = method(TIMES)
        assert rows.shape == (len(TIMES), size)
        np.testing.assert_allclose(rows[7], method(TIMES[7]), atol=1e-15)
    assert trajectory.angular_velocity(TIMES).shape == (len(TIMES), trajectory.space.rotation_size)


@ALL
def test_velocity_and_acceleration_are_central_differences_of_pose_and_velocity(trajectory):
    step = 1e-5
    t = SMOOTH_TIMES
    numeric_velocity = (trajectory.pose(t + step) - trajectory.pose(t - step)) / (2 * step)
    numeric_acceleration = (trajectory.velocity(t + step) - trajectory.velocity(t - step)) / (2 * step)
    # central differences: truncation ~ step^2 / 6 * |third derivative| (< 100 here) ~ 2e-9,
    # rounding ~ 1e-16 * |pose| (< 3) / step ~ 3e-11; 1e-7 leaves a wide margin
    np.testing.assert_allclose(trajectory.velocity(t), numeric_velocity, atol=1e-7)
    np.testing.assert_allclose(trajectory.acceleration(t), numeric_acceleration, atol=1e-7)


@SPACES
def test_ramped_circle_starts_from_rest_and_is_the_steady_circle_half_a_ramp_late(space):
    circle, steady = _ramped_circle(space)
    np.testing.assert_array_equal(circle.pose(0.0), steady.pose(0.0))
    # every entry, the rocking's rotation rate included, starts at rest
    np.testing.assert_allclose(circle.velocity(0.0), 0.0, atol=1e-15)
    np.testing.assert_allclose(circle.acceleration(0.0), 0.0, atol=1e-15)
    _, rate, rate_change = circle.phase(np.array([2.0, 3.0, 7.5]))
    np.testing.assert_allclose(rate, -0.7, atol=1e-15)
    np.testing.assert_allclose(rate_change, 0.0, atol=1e-15)
    speed = np.linalg.norm(circle.velocity(np.linspace(2.0, 8.0, 13))[:, :2], axis=1)
    np.testing.assert_allclose(speed, circle.radius * 0.7, atol=1e-15)
    t = np.linspace(2.0, 8.0, 13)
    for method in ("pose", "velocity", "acceleration"):
        np.testing.assert_allclose(getattr(circle, method)(t), getattr(steady, method)(t - 1.0), atol=1e-14)
    # the jerk is bounded: the acceleration jumps by ~1e-9 across the end of the ramp
    np.testing.assert_allclose(circle.acceleration(2.0 - 1e-9), circle.acceleration(2.0 + 1e-9), atol=1e-7)


def test_both_spaces_run_a_circle_with_one_phase_law():
    t = np.linspace(-1.0, 5.0, 61)
    planar, spatial = _ramped_circle(PLANE)[0], _ramped_circle(SPACE)[0]
    for flat, turning in zip(planar.phase(t), spatial.phase(t)):
        np.testing.assert_array_equal(flat, turning)


@SPACES
def test_circle_stays_at_its_radius_in_the_plane_of_the_first_two_position_axes(space):
    circle = _ramped_circle(space)[0]
    pose = circle.pose(np.linspace(-1.0, 12.0, 131))  # before, during and after the ramp
    offset = pose[:, :2] - np.array(circle.center[:2])
    np.testing.assert_allclose(np.hypot(offset[:, 0], offset[:, 1]), circle.radius, atol=1e-15)
    held = slice(2, space.position_size)  # the other position axes (z in space) never change
    np.testing.assert_array_equal(pose[:, held], np.tile(circle.center[held], (len(pose), 1)))
    np.testing.assert_array_equal(circle.velocity(TIMES)[:, held], 0.0)


@pytest.mark.parametrize("move", [PLANAR_MOVE, SPATIAL_MOVE], ids=["planar", "spatial"])
def test_point_to_point_is_rest_to_rest_and_holds_outside_the_motion(move):
    start, end = np.array(move.start), np.array(move.end)
    np.testing.assert_array_equal(move.pose(0.0), start)
    np.testing.assert_allclose(move.pose(2.0), end, atol=1e-15)
    np.testing.assert_allclose(move.pose(9.0), end, atol=1e-15)
    np.testing.assert_allclose(move.pose(1.25), 0.5 * (start + end), atol=1e-15)  # symmetric quintic
    for t in (0.5, 2.0):
        np.testing.assert_allclose(move.velocity(t), 0.0, atol=1e-15)
        np.testing.assert_allclose(move.acceleration(t), 0.0, atol=1e-12)
    np.testing.assert_array_equal(move.turning_times(5.0), [0.5, 2.0])


@pytest.mark.parametrize("hold", [TRAJECTORIES["planar_hold"], TRAJECTORIES["spatial_hold"]], ids=["planar", "spatial"])
def test_hold_is_constant_and_still(hold):
    np.testing.assert_array_equal(hold.pose(TIMES), np.tile(hold.held_pose, (len(TIMES), 1)))
    np.testing.assert_array_equal(hold.velocity(TIMES), 0.0)
    np.testing.assert_array_equal(hold.acceleration(3.0), np.zeros(hold.space.pose_size))


@SPACES
def test_circle_turning_times_are_the_quarter_turns_where_a_circled_axis_is_extreme(space):
    circle = replace(_ramped_circle(space)[1], angular_rate=1.5)
    times = circle.turning_times(5.0)
    np.testing.assert_allclose(np.diff(times), 0.5 * np.pi / 1.5, atol=1e-15)
    np.testing.assert_allclose(np.min(np.abs(circle.velocity(times)[:, :2]), axis=1), 0.0, atol=1e-15)
    assert _ramped_circle(space)[0].turning_times(5.0).size == 0  # ramped: no closed form
    assert replace(circle, radius=0.0).turning_times(5.0).size == (0 if space is PLANE else times.size)  # rocks
    with pytest.raises(SceneError, match="trajectory.angular_rate"):
        replace(circle, angular_rate=1e9).turning_times(5.0)


@ALL
def test_dict_round_trip_gives_an_equal_trajectory(trajectory):
    data = trajectory.to_dict()
    assert all(not isinstance(value, tuple) for value in data.values())  # TOML-friendly lists
    assert trajectory_from_dict(data, trajectory.space) == trajectory


def test_dicts_use_kind_and_field_names_and_a_circle_that_does_not_rock_has_no_tilt():
    assert trajectory_from_dict({"kind": "circle", "center": [0, -1.6]}, PLANE) == PAPER_CIRCLE
    assert PAPER_CIRCLE.to_dict() == {"kind": "circle", "center": [0.0, -1.6], "radius": 0.4, "angular_rate": 1.5,
                                      "rotation": 0.0, "ramp_time": 0.0}  # as the committed planar scene files
    assert RAMPED_TILTED_CIRCLE.to_dict()["tilt"] == [0.04, -0.03, 0.0]
    assert "tilt" not in replace(RAMPED_TILTED_CIRCLE, tilt=None).to_dict()
    for space, pose in ((PLANE, [0.0, -1.0, 0.0]), (SPACE, [0.0, 0.0, 1.0, 0.0, 0.0, 0.0])):
        hold = HoldTrajectory(tuple(pose), space=space)
        assert trajectory_from_dict({"kind": "hold", "pose": pose}, space) == hold
        assert hold.to_dict() == {"kind": "hold", "pose": [float(v) for v in pose]}
        move = trajectory_from_dict({"kind": "point_to_point", "start": pose, "end": pose, "duration": 2}, space)
        assert move.duration == 2.0 and move.end == tuple(pose) and move.space is space


#: A good centre and pose of each space, beside the bad value a case gives.
GOOD = {PLANE: {"center": [0.0, -1.6], "pose": [0.0, -2.0, 0.0]},
        SPACE: {"center": [0.0, 0.0, 2.0], "pose": [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]}}


@SPACES
@pytest.mark.parametrize("data, name", [
    ({"kind": "spiral"}, "trajectory.kind"),
    ({}, "trajectory.kind"),
    ({"kind": "circle", "speed": 1.0}, "speed"),
    ({"kind": "circle", "radius": np.nan}, "trajectory.radius"),
    ({"kind": "circle", "radius": -0.4}, r"trajectory.radius must be >= 0 \[m\], got -0.4"),
    ({"kind": "circle", "ramp_time": -1.0}, "trajectory.ramp_time"),
    ({"kind": "circle", "angular_rate": np.inf}, "trajectory.angular_rate"),
    ({"kind": "circle", "center": [0.0]}, "trajectory.center"),
    ({"kind": "circle", "center": [0.0, 0.0, 0.0, 0.0]}, "trajectory.center"),
    ({"kind": "circle", "tilt": [0.1, 0.0]}, "trajectory.tilt"),
    ({"kind": "circle", "rotation": "up"}, "trajectory.rotation"),
    ({"kind": "circle", "center": None}, "trajectory.center"),
    ({"kind": "hold", "pose": [0.0, "low", 0.0]}, "trajectory.pose"),
    ({"kind": "hold", "pose": [0.0, -2.0]}, "trajectory.pose"),
    ({"kind": "hold", "held_pose": "good"}, "held_pose"),
    ({"kind": "point_to_point", "duration": 0.0}, r"trajectory.duration must be > 0 \[s\]"),
    ({"kind": "point_to_point", "end": [0.0, np.inf, 0.0]}, "trajectory.end"),
    ({"kind": "point_to_point", "start_time": "now"}, "trajectory.start_time"),
])
def test_bad_trajectory_fields_raise_scene_error_naming_them(space, data, name):
    data = {**({"center": GOOD[space]["center"]} if data.get("kind") == "circle" else {}),
            **({"pose": GOOD[space]["pose"]} if data.get("kind") == "hold" else {}),
            **({"start": GOOD[space]["pose"], "end": GOOD[space]["pose"]} if data.get("kind") == "point_to_point"
               else {}), **data}
    with pytest.raises(SceneError, match=name):
        trajectory_from_dict(data, space)


@pytest.mark.parametrize("space, data, message", [
    (PLANE, {"kind": "circle"}, r"trajectory.center is required for kind 'circle' \(a position x \[m\], z \[m\]\)"),
    (SPACE, {"kind": "circle"}, r"trajectory.center is required .*\(a position x \[m\], y \[m\], z \[m\]\)"),
    (PLANE, {"kind": "hold"}, r"trajectory.pose is required .*\(a pose x \[m\], z \[m\], rotation \[rad\]\)"),
    (SPACE, {"kind": "hold"}, r"trajectory.pose is required .*\(a pose x \[m\], y \[m\], z \[m\], rx \[rad\], "
                              r"ry \[rad\], rz \[rad\]\)"),
    (PLANE, {"kind": "point_to_point", "end": [0, -2, 0]}, "trajectory.start is required"),
    (SPACE, {"kind": "point_to_point", "start": [0, 0, 1, 0, 0, 0]}, "trajectory.end is required"),
], ids=["planar_circle", "spatial_circle", "planar_hold", "spatial_hold", "planar_move", "spatial_move"])
def test_a_missing_position_or_pose_is_named_with_the_spaces_axes(space, data, message):
    with pytest.raises(SceneError, match=message):
        trajectory_from_dict(data, space)


def test_a_non_table_or_a_non_space_is_refused():
    with pytest.raises(SceneError, match="trajectory must be a table"):
        trajectory_from_dict([("kind", "hold")], PLANE)
    with pytest.raises(SceneError, match="trajectory.space"):
        HoldTrajectory((0.0, -2.0, 0.0), space=3)


@pytest.mark.parametrize("name, other", [("paper-circle", TRAJECTORIES["spatial_hold"]),
                                         ("spatial-cogiro", TRAJECTORIES["planar_hold"])])
def test_a_scene_refuses_a_trajectory_of_the_other_space(name, other):
    scene = load_scene(name)
    with pytest.raises(SceneError, match=f"trajectory must be a Trajectory of the {scene.space.name} space"):
        scene.with_changes(trajectory=other)


@ALL
def test_trajectories_are_frozen(trajectory):
    with pytest.raises(AttributeError):
        trajectory.space = SPACE


# ------------------------------------------------------------------ facts of one space


def test_the_planar_default_circle_is_the_papers_reference():
    t = np.linspace(0.0, 10.0, 41)
    expected = np.stack([0.4 * np.sin(1.5 * t), -1.6 - 0.4 * np.cos(1.5 * t), 0.0 * t], axis=-1)
    np.testing.assert_allclose(PAPER_CIRCLE.pose(t), expected, atol=1e-15)
    np.testing.assert_array_equal(PAPER_CIRCLE.pose(0.0), [0.0, -2.0, 0.0])  # the bottom of a vertical circle


def test_the_spatial_circle_is_horizontal_starts_below_the_centre_in_y_and_rocks_once_per_turn():
    circle = CircleTrajectory((0.0, 0.0, 2.0), radius=0.4, angular_rate=1.5, rotation=(0.0, 0.0, 0.1),
                              tilt=(0.05, 0.0, 0.0), space=SPACE)
    np.testing.assert_allclose(circle.pose(0.0), [0.0, -0.4, 2.0, 0.0, 0.0, 0.1], atol=1e-15)
    quarter = 0.5 * np.pi / 1.5
    np.testing.assert_allclose(circle.pose(quarter), [0.4, 0.0, 2.0, 0.05, 0.0, 0.1], atol=1e-15)
    np.testing.assert_allclose(circle.pose(4 * quarter), circle.pose(0.0), atol=1e-15)


def test_the_planar_rotation_rate_is_the_angular_velocity():
    rocking = TRAJECTORIES["planar_circle_rocking"]
    np.testing.assert_array_equal(rocking.angular_velocity(TIMES), rocking.velocity(TIMES)[:, 2:])


@pytest.mark.parametrize("circle", [
    RAMPED_TILTED_CIRCLE,
    CircleTrajectory((0.0, 0.0, 2.0), rotation=(0.0, 0.0, 1.2), tilt=(0.3, 0.0, 0.0), space=SPACE),
], ids=["small_tilt", "large_turn"])
def test_the_spatial_velocity_is_the_rotation_vector_rate_and_angular_velocity_converts_it(circle):
    t, step = 3.3, 1e-5
    # fixed-frame angular velocity from the rotation matrices: R(t+h) R(t-h)^T = exp(2h [omega]x) + O(h^3)
    change = rotation_from_vector(circle.pose(t + step)[3:]) @ rotation_from_vector(circle.pose(t - step)[3:]).T
    omega = rotation_vector(change) / (2 * step)
    theta, theta_rate = circle.pose(t)[3:], circle.velocity(t)[3:]
    np.testing.assert_allclose(omega, left_jacobian(theta) @ theta_rate, atol=1e-8)  # O(h^2) + 1e-16 / h
    np.testing.assert_allclose(circle.angular_velocity(t), omega, atol=1e-8)
    np.testing.assert_array_equal(circle.angular_velocity(np.array([t]))[0], circle.angular_velocity(t))
    # base rotation and tilt are not parallel: omega - theta' ~ (1 - cos a) / a^2 theta x theta' (a = |theta|,
    # the factor 1/2 for small a, 0.44 at a = 1.2) plus a smaller [theta]x^2 term
    expected_gap = 0.5 * np.linalg.norm(np.cross(theta, theta_rate))
    assert np.linalg.norm(omega - theta_rate) > 0.5 * expected_gap > 0.0


def test_planar_rotation_phi_is_the_spatial_rotation_about_minus_y():
    for phi in (0.3, -1.1, 2.5):
        spatial = rotation_from_vector((0.0, -phi, 0.0))
        np.testing.assert_allclose(spatial[np.ix_([0, 2], [0, 2])], rotation_matrix(phi), atol=1e-15)
        np.testing.assert_allclose(spatial[1], [0.0, 1.0, 0.0], atol=1e-15)  # y stays y


def test_a_move_in_the_x_z_plane_is_the_planar_move_embedded():
    spatial = PointToPointTrajectory(tuple(PLANE.embed(PLANAR_MOVE.start)), tuple(PLANE.embed(PLANAR_MOVE.end)),
                                     duration=1.5, start_time=0.5, space=SPACE)
    for method in ("pose", "velocity", "acceleration"):
        np.testing.assert_allclose(getattr(spatial, method)(TIMES), PLANE.embed(getattr(PLANAR_MOVE, method)(TIMES)),
                                   atol=1e-15)
    # and the platform anchors agree: planar r + R(phi) b, spatial r + exp([theta]x) (b_x, 0, b_z)
    anchor = np.array([[0.2, 0.05]])
    planar_points = PLANE.anchor_points(PLANAR_MOVE.pose(TIMES), anchor)
    spatial_points = SPACE.anchor_points(spatial.pose(TIMES), np.array([[0.2, 0.0, 0.05]]))
    np.testing.assert_allclose(spatial_points[..., [0, 2]], planar_points, atol=1e-15)
    np.testing.assert_allclose(spatial_points[..., 1], 0.0, atol=1e-15)


@pytest.mark.parametrize("name", ["paper-circle", "spatial-ipanema"])
def test_the_comparisons_smooth_start_ramps_a_circle_that_starts_at_full_speed_in_either_space(name):
    """``cdpr compare --ramp-time`` (:func:`smooth_start`): one circle class, so a spatial circle without a
    ramp of its own gets one too (it was left at full speed before the kinds were one)."""
    from cdpr_exu.studies.comparison import smooth_start

    scene = load_scene(name)
    full_speed = scene.with_changes(trajectory=replace(scene.trajectory, ramp_time=0.0))
    started = smooth_start(full_speed, 1.5)
    assert started.trajectory == replace(full_speed.trajectory, ramp_time=1.5)
    np.testing.assert_allclose(started.trajectory.velocity(0.0), 0.0, atol=1e-15)
    assert smooth_start(full_speed, 0.0) is full_speed
    ramped = full_speed.with_changes(trajectory=replace(full_speed.trajectory, ramp_time=0.5))
    assert smooth_start(ramped, 1.5) is ramped  # a circle with its own ramp keeps it


# ------------------------------------------------------------------ a new kind: one class, one entry


@dataclass(frozen=True)
class Bob(Trajectory):
    """A toy kind: the platform bobs up and down about ``around`` [m, rad], ``amplitude sin(rate t)`` along
    its space's vertical axis."""

    kind: ClassVar[str] = "bob"
    required_fields: ClassVar[dict[str, str]] = {"around": "pose"}

    around: tuple
    amplitude: float = 0.02
    rate: float = 2.0

    def __post_init__(self):
        super().__post_init__()
        if len(self.around) != self.space.pose_size:
            raise SceneError(f"trajectory.around must have {self.space.pose_size} entries, got {list(self.around)}")

    def _along(self, t, value):
        t = np.asarray(t, dtype=float)
        out = np.zeros(t.shape + (self.space.pose_size,))
        out[..., self.space.vertical] = value
        return out

    def pose(self, t):
        return np.asarray(self.around) + self._along(t, self.amplitude * np.sin(self.rate * np.asarray(t)))

    def velocity(self, t):
        return self._along(t, self.amplitude * self.rate * np.cos(self.rate * np.asarray(t)))

    def acceleration(self, t):
        return self._along(t, -self.amplitude * self.rate**2 * np.sin(self.rate * np.asarray(t)))


@pytest.mark.parametrize("name, around", [
    ("paper-circle", [0.0, -2.0, 0.0]),
    ("spatial-cogiro", [-0.034, -0.013, 2.265, 0.0, 0.0, 0.0]),  # the start of its own circle
])
def test_a_kind_registered_at_test_time_loads_in_a_planar_and_a_spatial_scene(monkeypatch, tmp_path, name, around):
    monkeypatch.setitem(TRAJECTORY_KINDS, "bob", Bob)
    data = load_scene(name).to_dict()
    data["trajectory"] = {"kind": "bob", "around": around, "amplitude": 0.03}
    scene = scene_from_dict(data)
    assert isinstance(scene.trajectory, Bob) and scene.trajectory.space is scene.space
    top = np.array(around)
    top[scene.space.vertical] += 0.03  # a quarter period in: 3 cm up, z in either space
    np.testing.assert_allclose(scene.trajectory.pose(np.pi / 4), top, atol=1e-15)
    # saved and loaded back as the same scene
    assert load_scene(save_scene(scene, tmp_path / "bob.toml")) == scene
    # the ideal kinematics follow it: each cable's length changes at u . v, the rate of its length
    t = np.linspace(0.0, 2.0, 21)
    lengths, rates = ideal_paid_out(scene, scene.trajectory.pose(t), scene.trajectory.velocity(t))
    step = 1e-6
    numeric = (ideal_paid_out(scene, scene.trajectory.pose(t + step))[0]
               - ideal_paid_out(scene, scene.trajectory.pose(t - step))[0]) / (2 * step)
    np.testing.assert_allclose(rates, numeric, atol=1e-7)  # O(step^2) + 1e-16 m / 1e-6 s
    assert np.ptp(lengths, axis=0).max() > 0.01  # the bob moves the cables: 3 cm up and down
    # the scene's space decides the pose size: a pose of the other space is refused, naming the field
    data["trajectory"]["around"] = around[:3] if len(around) == 6 else around + [0.0, 0.0, 0.0]
    with pytest.raises(SceneError, match="trajectory.around"):
        scene_from_dict(data)
    with pytest.raises(SceneError, match="trajectory.kind must be one of .*'bob'"):
        trajectory_from_dict({"kind": "wobble"}, scene.space)


# ------------------------------------------------------------------ waypoints and trajectory files (issue 26)

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_and_place" / "scene.toml"
SPATIAL_HEADER = "time_s,x_m,y_m,z_m,rotation_x_rad,rotation_y_rad,rotation_z_rad"


@pytest.mark.parametrize("path", [PLANAR_WAYPOINTS, SPATIAL_WAYPOINTS], ids=["planar", "spatial"])
def test_the_spline_passes_every_waypoint_with_continuous_rates_and_starts_and_ends_at_rest(path):
    times, poses = np.array(path.times), np.array(path.poses)
    np.testing.assert_allclose(path.pose(times), poses, atol=1e-14)  # interpolation: round-off only
    # left and right of each knot 1e-7 s apart: a jump would show at its full size; a continuous rate
    # moves by |next derivative| * 2e-7 (< 1e-4 here), so 1e-4 separates the two
    for rate in (path.velocity, path.acceleration):
        np.testing.assert_allclose(rate(times - 1e-7), rate(times + 1e-7), atol=1e-4)
    for t in (times[0], times[-1], times[0] - 1.0, times[-1] + 1.0):  # at rest at both ends and held outside
        np.testing.assert_allclose(path.velocity(t), 0.0, atol=1e-12)
        np.testing.assert_allclose(path.acceleration(t), 0.0, atol=1e-12)
    np.testing.assert_array_equal(path.pose(times[-1] + 3.0), path.pose(times[-1]))


@pytest.mark.parametrize("path", [PLANAR_WAYPOINTS, SPATIAL_WAYPOINTS], ids=["planar", "spatial"])
def test_the_turning_times_are_the_waypoints_and_each_pose_entrys_extremes(path):
    turning = path.turning_times(10.0)
    assert set(path.times) <= set(turning)
    inner = turning[(turning > path.times[0]) & (turning < path.times[-1]) & ~np.isin(turning, path.times)]
    assert inner.size and np.all(np.min(np.abs(path.velocity(inner)), axis=1) < 1e-9)  # a rate's root each
    # so the checked samples hold the extremes of every entry: a dense sampling finds none beyond them
    dense = path.pose(np.linspace(0.0, 10.0, 20001))
    checked = path.pose(turning)
    assert np.all(dense.max(axis=0) <= checked.max(axis=0) + 1e-12)
    assert np.all(dense.min(axis=0) >= checked.min(axis=0) - 1e-12)


@pytest.mark.parametrize("data, message", [
    ({"times": [0.0, 1.0, 1.0], "poses": [[0, -2, 0]] * 3}, r"trajectory.times must increase strictly: times\[2\]"),
    ({"times": [0.0], "poses": [[0, -2, 0]]}, "trajectory.times must give at least 2 times"),
    ({"times": [0.0, 1.0], "poses": [[0, -2, 0]]}, r"trajectory.poses must give one pose per time \(2\), got 1"),
    ({"times": [0.0, np.nan], "poses": [[0, -2, 0]] * 2}, r"trajectory.times\[1\] must be finite"),
    ({"times": [0.0, 1.0], "poses": [[0, -2, 0], [0, -2]]}, r"trajectory.poses\[1\] must have 3 entries"),
    ({"times": [0.0, 1.0]}, "trajectory.poses is required for kind 'waypoints' .one pose per time"),
    ({"times": "soon", "poses": []}, "trajectory.times must be a list"),
])
def test_bad_waypoints_are_refused_naming_the_field(data, message):
    with pytest.raises(SceneError, match=message):
        trajectory_from_dict({"kind": "waypoints", **data}, PLANE)


def _file_scene(folder, csv_text: str, name: str = "spatial-cogiro", path: str = "path.csv") -> Path:
    """A scene file in ``folder`` whose trajectory reads ``csv_text`` (written as ``path.csv``) beside it."""
    (folder / "path.csv").write_text(csv_text)
    data = load_scene(name).to_dict()
    data["trajectory"] = {"kind": "file", "path": path}
    scene = folder / "scene.toml"
    scene.write_text(tomli_w.dumps(data))
    return scene


def test_a_file_is_read_relative_to_the_scene_file_as_the_waypoints_it_holds(tmp_path, monkeypatch):
    rows = [(0.0, *SPATIAL_WAYPOINTS.poses[0]), (1.5, *SPATIAL_WAYPOINTS.poses[1]), (4.0, *SPATIAL_WAYPOINTS.poses[2])]
    # a run's pose.csv names its columns so, reference columns after them (ignored)
    text = SPATIAL_HEADER + ",x_ref_m\n" + "".join(",".join(map(str, row)) + ",9\n" for row in rows)
    scene_file = _file_scene(tmp_path, text)
    monkeypatch.chdir(tmp_path.parent)  # not the scene's folder: the path is read relative to the scene file
    scene = load_scene(scene_file)
    assert scene.trajectory == replace(SPATIAL_WAYPOINTS, times=(0.0, 1.5, 4.0))
    assert load_scene(save_scene(scene, tmp_path / "saved" / "scene.toml")) == scene  # saved as waypoints, no file
    assert set(scene.trajectory.times) <= set(reference_samples(scene)[0])  # the workspace check samples each
    # a run's own pose.csv reads back as the path its platform took
    run = Path(__file__).resolve().parents[1] / "results" / "pick-and-place"
    taken = trajectory_from_dict({"kind": "file", "path": "pose.csv"}, SPACE, run)
    np.testing.assert_allclose(taken.poses, np.loadtxt(run / "pose.csv", delimiter=",", skiprows=1)[:, 1:7], rtol=1e-15)


@pytest.mark.parametrize("name, text, message", [
    ("spatial-cogiro", "time_s,x_m,y_m,z_m,rotation_x_rad,rotation_y_rad\n0,0,0,2.3,0,0\n1,0,0,2.4,0,0\n",
     r"trajectory.path 'path.csv' lacks the column\(s\) rotation_z_rad: a spatial trajectory file's header names"),
    ("spatial-cogiro", "time_s,x_m,z_m,rotation_rad\n0,0,2.3,0\n1,0,2.4,0\n",
     r"lacks the column\(s\) y_m, rotation_x_rad, rotation_y_rad, rotation_z_rad: .*\(6 pose columns"),
    ("paper-circle", SPATIAL_HEADER + "\n0,0,0,-2,0,0,0\n1,0,0,-2,0,0,0\n", r"lacks the column\(s\) rotation_rad: a "
     r"planar trajectory file's header names time_s, x_m, z_m, rotation_rad \(3 pose columns"),
    ("spatial-cogiro", SPATIAL_HEADER + "\n0,0,0,2.3,0,0,0\n1,0,0,2.4,0,0,0\n1,0,0,2.5,0,0,0\n",
     r"line k \+ 2 read as times\[k\].*times must increase strictly: times\[2\] = 1 s follows times\[1\] = 1 s"),
    ("spatial-cogiro", SPATIAL_HEADER + "\n0,0,0,2.3,0,0,0\n1,0,0,nan,0,0,0\n",
     r"trajectory.poses\[1\]\[2\] must be finite, got nan"),
    ("spatial-cogiro", SPATIAL_HEADER + "\n0,0,0,2.3,0,0,0\ninf,0,0,2.3,0,0,0\n", r"trajectory.times\[1\] must be finite"),
    ("spatial-cogiro", SPATIAL_HEADER + "\n0,0,0,2.3,0,0,0\n", "trajectory.times must give at least 2 times"),
    ("spatial-cogiro", SPATIAL_HEADER + "\n0,0,0,2.3,0,0,0\n1,0,0,high,0,0,0\n",
     r"trajectory.path 'path.csv', line 3: \['1', '0', '0', 'high', '0', '0', '0'\] does not give a number"),
    ("spatial-cogiro", "", r"lacks the column\(s\) time_s, x_m"),
], ids=["missing_column", "planar_file_spatial_scene", "spatial_file_planar_scene", "times_not_increasing", "nan",
        "inf", "one_row", "text", "empty"])
def test_cdpr_run_refuses_a_bad_trajectory_file_naming_it_and_writes_nothing(tmp_path, capsys, name, text, message):
    out = tmp_path / "out"
    assert main(["run", str(_file_scene(tmp_path, text, name)), "--out", str(out)]) == 2
    assert re.search(message, capsys.readouterr().err) and not out.exists()


def test_cdpr_run_refuses_a_trajectory_file_that_is_not_there_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(_file_scene(tmp_path, "", path="paths/none.csv")), "--out", str(out)]) == 2
    assert re.search(r"trajectory.path 'paths/none.csv': cannot read .*none.csv: No such file", capsys.readouterr().err)
    assert not out.exists()


@pytest.mark.slow
def test_a_planar_robot_under_ideal_ik_follows_a_waypoints_path():
    # a diamond through the paper circle's range (x +-0.3 m, z -2.0 .. -1.4 m) in 6 s, from the paper's start
    corners = [(0.0, -2.0, 0.0), (0.3, -1.7, 0.0), (0.0, -1.4, 0.0), (-0.3, -1.7, 0.0), (0.0, -2.0, 0.0)]
    scene = load_scene("paper-circle")
    scene = scene.with_changes(trajectory=WaypointsTrajectory((0.0, 1.5, 3.0, 4.5, 6.0), tuple(corners)),
                               solver=replace(scene.solver, end_time=6.0))
    summary = simulate(scene).summary()
    # What ideal IK leaves on this robot is the heavy cables' sag and the platform's swing: on the
    # paper circle (0.6 m/s) 5.9 cm / 4.4 cm in x / z (results/paper_circle); on this path (up to
    # 0.46 m/s, corners rounded by the spline) 3.6 cm / 2.6 cm measured. 5 cm bounds both, as on the
    # circle, while a path followed wrongly (a wrong rate, a lag) would miss by the 0.3 m of a leg.
    assert summary["status"] == "completed"
    assert summary["max_abs_error_x_m"] < 0.05 and summary["max_abs_error_z_m"] < 0.05


@pytest.mark.slow
def test_the_cogiro_class_robot_follows_the_pick_and_place_path_from_its_file():
    scene = load_scene(EXAMPLE)  # examples/pick_and_place: path.csv beside it
    assert isinstance(scene.trajectory, WaypointsTrajectory) and len(scene.trajectory.times) == 41
    summary = simulate(scene.with_changes(cables=tuple(replace(c, n_elements=10) for c in scene.cables))).summary()
    # Ideal IK on spatial-cogiro's circle leaves 0.60 mm (sag and stretch, results/spatial); this path
    # lifts, carries and lowers the platform by metres at up to 0.9 m/s^2: 1.49 mm measured with 20
    # elements (results/pick-and-place), 1.47 mm with 10. 3 mm bounds it, 0.1 % of the 3 m path.
    assert summary["status"] == "completed" and summary["max_position_error_m"] < 3e-3
    assert summary["min_element_tension_N"] > 100.0  # CASPR's lower limit: taut throughout
    assert summary["max_rotation_error_deg"] < 0.1
