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
    """Ideal IK evaluated at each step: paid out = initial + l(ref(t)) - l(ref(0)) [m], rate dl/dt [m/s]."""

    name = "direct_ik"
    uses_pose = False
    uses_tension = False

    def reset(self, scene, initial_paid_out) -> None:
        self.scene, self.initial = scene, np.asarray(initial_paid_out, dtype=float)
        self.start = ideal_paid_out(scene, scene.trajectory.pose(np.zeros(1)))[0][0]

    def command(self, measurement: Measurement) -> WinchCommand:
        t = np.array([measurement.time])
        lengths, rates = ideal_paid_out(self.scene, self.scene.trajectory.pose(t), self.scene.trajectory.velocity(t))
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
