"""A controller written once, outside the library, runs on planar and spatial robots (issue 24, evidence).

The toy is ideal inverse kinematics without a table: at every step it asks the one kinematics
(:func:`cdpr_exu.statics.kinematics.ideal_paid_out`) for the ideal lengths and rates at the
reference's pose of the measured time, and never asks which dimension it is in. Run through the
one :func:`cdpr_exu.simulate`, it must follow the shipped :class:`IdealIKController` (which reads
the same lengths from a table on the step grid, linear between steps) in both dimensions.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import cdpr_exu
from cdpr_exu.statics.kinematics import ideal_paid_out
from controllers.base import Measurement, WinchCommand


class DirectIK:
    """Ideal IK evaluated at each step: paid out = initial + l(p(t)) - l(p(0)) [m], rate dl/dt [m/s], for a
    motion ``p`` (``motion(t) -> (pose, rate)``; default the scene's reference)."""

    name = "direct_ik"
    uses_pose = False
    uses_tension = False

    def __init__(self, motion=None):
        self.motion = motion

    def reset(self, scene, initial_paid_out, **kwargs) -> None:
        self.scene, self.initial = scene, np.asarray(initial_paid_out, dtype=float)
        self.motion = self.motion or (lambda t: (scene.trajectory.pose(t), scene.trajectory.velocity(t)))
        self.start = ideal_paid_out(scene, *self.motion(np.zeros(1)))[0][0]

    def command(self, measurement: Measurement) -> WinchCommand:
        lengths, rates = ideal_paid_out(self.scene, *self.motion(np.array([measurement.time])))
        return WinchCommand(self.initial + lengths[0] - self.start, rates[0])


@pytest.mark.parametrize("name", ["paper-circle-slow", "spatial-cogiro"])
def test_a_toy_controller_written_once_runs_on_both_dimensions_and_matches_ideal_ik(name):
    scene = cdpr_exu.load_scene(name)
    scene = scene.with_changes(solver=replace(scene.solver, end_time=0.4))
    toy = cdpr_exu.simulate(scene, DirectIK())
    shipped = cdpr_exu.simulate(scene, cdpr_exu.IdealIKController())
    assert type(toy) is type(shipped) is cdpr_exu.Result and toy.status == shipped.status == "completed"
    assert toy.pose.shape == shipped.pose.shape == (len(shipped.time), scene.space.pose_size)
    # The two commands differ only by the table's linear interpolation between solver steps (and the
    # solver's iterates): the paths agree far below the model's own errors (measured: 4e-10 m planar, 4e-16 m
    # spatial, against ideal IK's own 7.2 mm and 0.13 mm from the reference over these 0.4 s).
    gap = np.abs(toy.position - shipped.position).max()
    assert gap < 1e-6, f"{name}: the toy's path is {gap:.3g} m from ideal IK's"
    # and the toy really moved the winches: its lengths follow the reference, not a constant
    assert np.ptp(toy.paid_out, axis=0).max() > 1e-3


def _smooth(t, start, duration):
    """The quintic rest-to-rest step from 0 to 1 over [start, start + duration] [s], and its rate [1/s]."""
    tau = np.clip((t - start) / duration, 0.0, 1.0)
    return tau**3 * (10 - 15 * tau + 6 * tau**2), 30 * tau**2 * (1 - tau) ** 2 / duration


class Watcher(DirectIK):
    """:class:`DirectIK` that also reads the measured pose: keeps (state time, pose, velocity) of every step."""

    name = "watcher"
    uses_pose = True

    def reset(self, scene, initial_paid_out, **kwargs) -> None:
        super().reset(scene, initial_paid_out)
        self.seen = []

    def command(self, measurement: Measurement) -> WinchCommand:
        if measurement.state_time is not None:
            self.seen.append((measurement.state_time, measurement.platform_pose.copy(),
                              measurement.platform_velocity.copy()))
        return super().command(measurement)


@pytest.mark.parametrize("name", ["paper-circle-slow", "spatial-cogiro"])
def test_the_measured_velocity_is_the_poses_rate_in_both_dimensions(name):
    """One convention for ``Measurement.platform_velocity``: the time derivative of the measured pose (in
    space the rotation vector's rate, not Exudyn's angular velocity), checked against central differences
    of the measured poses over the solver's steps. In space the winches turn the platform 0.1 rad about x,
    then 0.1 rad about z: during the second turn the rotation vector is not parallel to its rate, so the
    angular velocity differs from the rate by about |theta| |rate| / 2 (checked: the test tells them apart)."""
    scene = cdpr_exu.load_scene(name)
    space = scene.space
    motion = None
    if space.dimension == 3:
        rest = np.asarray(scene.trajectory.pose(np.zeros(1)))[0]

        def motion(t):
            (a, da), (b, db) = _smooth(t, 0.0, 0.4), _smooth(t, 0.4, 0.4)
            turn_x, turn_z = np.array([0, 0, 0, 0.1, 0, 0]), np.array([0, 0, 0, 0, 0, 0.1])
            return rest + np.outer(a, turn_x) + np.outer(b, turn_z), np.outer(da, turn_x) + np.outer(db, turn_z)
    scene = scene.with_changes(solver=replace(scene.solver, end_time=0.8))
    watcher = Watcher(motion)
    assert cdpr_exu.simulate(scene, watcher).status == "completed"
    times = np.array([s[0] for s in watcher.seen])
    poses = np.array([s[1] for s in watcher.seen])
    rates = np.array([s[2] for s in watcher.seen])
    keep = np.flatnonzero(np.diff(times) > 0)  # one row per solver state
    times, poses, rates = times[keep], poses[keep], rates[keep]
    difference = (poses[2:] - poses[:-2]) / (times[2:] - times[:-2])[:, None]
    # after the planar start-up from straight cables (the first 0.2 s ring at the element frequencies, which
    # two steps cannot resolve); central differences over 2 x 1e-2 s err by h^2 |third derivative| / 6 and
    # the dynamics: measured 3.7e-3 rad/s in space (rates up to 0.48 rad/s; the angular velocity is 0.023 rad/s
    # from them), 1.6e-5 in the plane
    later = times[1:-1] > 0.2
    tolerance = 0.01 * np.abs(rates).max()
    assert np.abs(difference - rates[1:-1])[later].max() < tolerance
    if space.dimension == 3:  # Exudyn's angular velocity, the old convention, would fail the same check
        rotation = slice(space.position_size, None)
        omega = space.angular_velocity(poses[1:-1, rotation], rates[1:-1, rotation])
        assert np.abs(difference[:, rotation] - omega)[later].max() > 3 * tolerance
