"""Joint-space control from the ideal inverse kinematics (the paper's scheme).

The cables are taken as straight, massless and inextensible: the paid-out length of
cable i is the straight length from its pulley's tangent point to the anchor plus the
arc it wraps on the pulley, evaluated on the reference pose. The winch follows it
open-loop; sag and stretch are ignored, which is the error the paper measures.
"""

from __future__ import annotations

import numpy as np

from cdpr_exu.statics.kinematics import ideal_paid_out

from .base import Measurement, WinchCommand


def table_lookup(t: float, times: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Row of ``table`` (shape (K, m)) at time ``t`` [s], linear between ``times`` (shape (K,), increasing).

    ``np.interp`` on every column, in one pass: the same formula, so the same bits
    (``fp[j] + slope (t - xp[j])``, the end values outside the table, the table's
    value where ``t`` hits a sample).
    """
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
    """Open-loop winch lengths from ideal (straight, massless, inextensible) cables.

    As in the paper, the ideal length is imposed as a velocity (flow) source: the
    command is the initial paid-out length plus the change of the ideal length since
    t = 0. The table is computed once per run on the solver's step grid and read by
    linear interpolation, so a step costs no inverse kinematics.
    """

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
