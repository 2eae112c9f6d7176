"""Tension-aware joint-space control of spatial robots: sag and stretch from the elastic catenaries.

At samples of the reference (every :data:`SAMPLE_PERIOD` s) the controller solves the
inverse spatial statics (:func:`cdpr_exu.physics.spatial_statics.solve_inverse_spatial_statics`):
the unstrained lengths whose elastic catenaries hold the platform at the reference pose,
with the reference's acceleration as a d'Alembert force, and the tensions nearest the
previous sample's, starting from the tensions the robot actually has at rest (the
catenary statics of its initial lengths). An over-constrained robot so keeps the internal
tension it started with. The command is the initial paid-out length plus the change of
these lengths, interpolated by a cubic spline (its derivative is the rate). Open loop:
it reads neither pose nor tension. Units SI.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from .base import Measurement, WinchCommand

#: Spacing of the statics samples along the reference [s].
SAMPLE_PERIOD = 0.02


class SpatialTensionAwareController:
    """Lengths of the elastic catenaries that hold the reference pose (spatial scenes)."""

    name = "tension_aware"
    uses_pose = False
    uses_tension = False

    def __init__(self, sample_period: float = SAMPLE_PERIOD) -> None:
        self.sample_period = float(sample_period)
        self._spline = None

    def reset(self, scene, initial_paid_out) -> None:
        """Solve the inverse statics along ``scene.trajectory`` and tabulate the commands.

        Raises
        ------
        UnreachableError
            If a sampled reference pose cannot be held by cables that pull.
        """
        from cdpr_exu.core.errors import UnreachableError
        from cdpr_exu.physics.spatial_statics import solve_inverse_spatial_statics, solve_spatial_statics

        platform = scene.catenary_platform()
        initial = np.asarray(initial_paid_out, dtype=float)
        rest = solve_spatial_statics(platform, initial)
        tensions = np.array([c.catenary.horizontal_tension for c in rest.cables])
        end = scene.solver.end_time
        times = np.linspace(0.0, end, max(int(np.ceil(end / self.sample_period)), 3) + 1)
        poses = np.atleast_2d(scene.trajectory.pose(times))
        accelerations = np.atleast_2d(scene.trajectory.acceleration(times))
        lengths = np.empty((len(times), len(initial)))
        for k, (t, pose, acceleration) in enumerate(zip(times, poses, accelerations)):
            inertial = np.concatenate([-platform.mass * acceleration[:3], np.zeros(3)])
            try:
                inverse = solve_inverse_spatial_statics(platform, pose, tensions, external_wrench=inertial)
            except UnreachableError as err:
                raise UnreachableError(f"the reference at t = {t:.3f} s: {err}") from None
            lengths[k] = inverse.unstrained_lengths
            tensions = inverse.horizontal_tensions
        self._spline = CubicSpline(times, initial + lengths - lengths[0], axis=0)
        self._rate = self._spline.derivative()

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._spline is None:
            raise RuntimeError("SpatialTensionAwareController.reset(scene) must be called before command()")
        t = measurement.time
        return WinchCommand(np.asarray(self._spline(t), dtype=float), np.asarray(self._rate(t), dtype=float))
