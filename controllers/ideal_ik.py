"""Joint-space control from the ideal inverse kinematics (the paper's scheme): the ideal cable lengths
of the reference pose, open loop; sag and stretch are ignored, which is the error the paper measures."""

from __future__ import annotations

import numpy as np

from cdpr_exu.statics.kinematics import ideal_paid_out

from .base import Measurement, WinchCommand


def table_lookup(t: float, times: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Row of ``table`` (K, m) at time ``t`` [s], linear between ``times`` (K,): ``np.interp`` on every
    column in one pass, the same formula and so the same bits."""
    j = int(np.searchsorted(times, t, side="right")) - 1
    if j < 0:
        return table[0].copy()
    if j >= times.size - 1:
        return table[-1].copy()
    if t == times[j]:
        return table[j].copy()
    slope = (table[j + 1] - table[j]) / (times[j + 1] - times[j])
    return slope * (t - times[j]) + table[j]


class IdealIKController:
    """Open-loop winch lengths from ideal cables: the initial paid-out length plus the ideal length's change
    since t = 0 (the paper's flow source), tabulated on the step grid once per run."""

    name = "ideal_ik"
    uses_pose = False
    uses_tension = False

    def __init__(self) -> None:
        self._times = None
        self._lengths = None
        self._rates = None

    def reset(self, scene, initial_paid_out) -> None:
        """Tabulate the commands for ``scene.trajectory`` on the step grid."""
        solver = scene.solver
        self._times = np.linspace(0.0, solver.end_time, solver.n_steps + 1)
        poses = scene.trajectory.pose(self._times)
        rates = scene.trajectory.velocity(self._times)
        lengths, self._rates = ideal_paid_out(scene, poses, rates)
        self._lengths = np.asarray(initial_paid_out, dtype=float) + lengths - lengths[0]

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._times is None:
            raise RuntimeError("IdealIKController.reset(scene) must be called before command()")
        t = measurement.time
        return WinchCommand(table_lookup(t, self._times, self._lengths), table_lookup(t, self._times, self._rates))
